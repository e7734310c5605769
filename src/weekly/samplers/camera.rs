//! The checks of the camera's random parts: the jitter strata, the lens disk, the ray time.

use super::*;

/// One stratum of the camera's jittered sampling.
#[derive(Clone, Copy, Debug)]
pub struct JitterSetting {
    /// The stratum `(s_i, s_j)`.
    pub stratum: (u32, u32),
    /// The course's step, `one_over_sqrt_spp` frozen from the default spp (1/3 in week 9,
    /// `1/sqrt(10)` in week 10).
    pub step: f64,
    /// The step recomputed from the scene's spp, `1 / floor(sqrt(spp))`.
    pub unfrozen_step: f64,
}

impl JitterSetting {
    /// The offsets `0.5 (-0.5 + step (s + U))` (`half`) or `-0.5 + step (s + U)`, as a
    /// hypothesis on `[px, py]`.
    fn hypothesis(
        &self,
        name: &'static str,
        standing: Standing,
        says: &str,
        step: f64,
        half: bool,
    ) -> Hypothesis {
        let (si, sj) = (self.stratum.0 as f64, self.stratum.1 as f64);
        let scale = if half { 0.5 } else { 1.0 };
        let unit = move |p: f64, s: f64| (p / scale + 0.5) / step - s;
        let course = standing == Standing::Course;
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                let (ux, uy) = (unit(s[0], si), unit(s[1], sj));
                let inside = |u: f64| (-1e-9..=1.0 + 1e-9).contains(&u);
                if inside(ux) && inside(uy) {
                    Ok(())
                } else if course {
                    let lo = |s: f64| scale * (-0.5 + step * s);
                    Err(format!(
                        "the sample lies at ({:?}, {:?}) pixels from the pixel's centre, outside its stratum [{:.4}, {:.4}] x [{:.4}, {:.4}]",
                        s[0],
                        s[1],
                        lo(si),
                        lo(si + 1.0),
                        lo(sj),
                        lo(sj + 1.0)
                    ))
                } else {
                    Err("outside".into())
                }
            }),
            (
                SQUARE_CELLS,
                Box::new(move |s| square_cell(unit(s[0], si), unit(s[1], sj))),
            ),
            Probs::Equal,
            Box::new(move |r| {
                let px = scale * (-0.5 + step * (si + r.next_f64()));
                let py = scale * (-0.5 + step * (sj + r.next_f64()));
                [px, py, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            }),
        )
    }
}

impl SamplerCheck {
    /// The jittered sample of stratum `setting.stratum`: `0.5 (-0.5 + step (s + U))` pixels from
    /// the pixel's centre, `U` uniform in `[0, 1)` on each axis.
    pub fn jitter(setting: JitterSetting) -> Self {
        let j = setting;
        let mut mistakes = vec![
            j.hypothesis(
                "jitter_outside_pixel",
                Standing::Mistake,
                "the stratum step one_over_sqrt_spp left out: -0.5 + (s + U) reaches far outside the pixel",
                1.0,
                true,
            ),
            j.hypothesis(
                "jitter_without_half",
                Standing::Mistake,
                "the offsets not halved: -0.5 + step (s + U) instead of 0.5 (-0.5 + step (s + U))",
                j.step,
                false,
            ),
            Hypothesis::new(
                "jitter_ignores_stratum",
                Standing::Mistake,
                "a uniform point of the whole pixel (get_ray's), not of the stratum",
                Box::new(|s| {
                    finite(s)?;
                    if s[0].abs() <= 0.5 + 1e-9 && s[1].abs() <= 0.5 + 1e-9 {
                        Ok(())
                    } else {
                        Err("outside the pixel".into())
                    }
                }),
                (SQUARE_CELLS, Box::new(|s| square_cell(s[0] + 0.5, s[1] + 0.5))),
                Probs::Equal,
                Box::new(|r| {
                    [r.next_f64() - 0.5, r.next_f64() - 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            ),
        ];
        if (j.unfrozen_step - j.step).abs() > 1e-12 {
            mistakes.push(j.hypothesis(
                "jitter_step_not_frozen",
                Standing::Physical,
                "the stratum step recomputed from the scene's spp, 1 / floor(sqrt(spp)) (the strata then tile the pixel's centre region as intended; the course freezes the step at the default spp 10)",
                j.unfrozen_step,
                true,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::JitterStratum,
            samples: CAMERA_SAMPLES,
            course: j.hypothesis(
                "course",
                Standing::Course,
                "0.5 (-0.5 + step (s + U)) pixels from the pixel's centre on each axis, U uniform in [0, 1), step the course's frozen one_over_sqrt_spp",
                j.step,
                true,
            ),
            mistakes,
        }
    }

    /// The lens: ray origins uniform on the defocus disk of radius 1 (in units of the course's
    /// radius) in the camera's `(u, v)` plane. `doubled` is the radius ratio of the
    /// doubled-angle mistake, `tan(angle) / tan(angle / 2)`.
    pub fn lens(doubled: f64) -> Self {
        let disk = |name, standing, says: &str, radius: f64| {
            Hypothesis::new(
                name,
                standing,
                says,
                Box::new(move |s: &Sample| {
                    finite(s)?;
                    if s[2].abs() > 1e-9 {
                        return Err(format!(
                            "the ray starts {:?} off the lens plane (along the camera's w)",
                            s[2]
                        ));
                    }
                    let r2 = (s[0] * s[0] + s[1] * s[1]) / (radius * radius);
                    if r2 <= 1.0 + 1e-9 {
                        Ok(())
                    } else {
                        Err(format!(
                            "the ray starts {:?} lens radii from the camera's centre, outside the lens",
                            r2.sqrt() * radius
                        ))
                    }
                }),
                (
                    DISK_CELLS,
                    Box::new(move |s: &Sample| disk_cell(s[0] / radius, s[1] / radius)),
                ),
                Probs::Equal,
                Box::new(move |r: &mut PixelSampler| {
                    let (x, y) = r.in_unit_disk();
                    [radius * x, radius * y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            )
        };
        SamplerCheck {
            kind: SamplerKind::LensDisk,
            samples: CAMERA_SAMPLES,
            course: disk(
                "course",
                Standing::Course,
                "origins uniform on the defocus disk (radius focus tan(angle / 2)) in the camera's u, v plane",
                1.0,
            ),
            mistakes: vec![
                Hypothesis::new(
                    "jittered_ray_without_lens",
                    Standing::Mistake,
                    "every ray starts at the camera's centre: the jittered path has no lens (the week-10 skeleton's)",
                    Box::new(|s| {
                        finite(s)?;
                        if s[0].abs() <= 1e-9 && s[1].abs() <= 1e-9 {
                            Ok(())
                        } else {
                            Err("off the centre".into())
                        }
                    }),
                    (1, Box::new(|_| 0)),
                    Probs::Equal,
                    Box::new(|_| [0.0; 9]),
                ),
                disk(
                    "defocus_radius_doubled",
                    Standing::Mistake,
                    "a lens of radius focus tan(angle) instead of focus tan(angle / 2)",
                    doubled,
                ),
                square_hypothesis(|r| {
                    let p = mistakes::in_square(r);
                    [p.x, p.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            ],
        }
    }

    /// The camera ray's time: uniform in `[0, 1)`.
    pub fn ray_time() -> Self {
        SamplerCheck {
            kind: SamplerKind::RayTime,
            samples: CAMERA_SAMPLES,
            course: Hypothesis::new(
                "course",
                Standing::Course,
                "a time uniform in [0, 1)",
                Box::new(|s| {
                    finite(s)?;
                    if (0.0..=1.0).contains(&s[0]) {
                        Ok(())
                    } else {
                        Err(format!("the ray's time {:?} is outside [0, 1)", s[0]))
                    }
                }),
                (20, Box::new(|s| ((s[0] * 20.0) as usize).min(19))),
                Probs::Equal,
                Box::new(|r| [r.next_f64(), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            ),
            mistakes: vec![Hypothesis::new(
                "jittered_ray_without_time",
                Standing::Mistake,
                "every ray has time 0: no motion blur",
                Box::new(|s| {
                    finite(s)?;
                    if s[0] == 0.0 {
                        Ok(())
                    } else {
                        Err("not 0".into())
                    }
                }),
                (1, Box::new(|_| 0)),
                Probs::Equal,
                Box::new(|_| [0.0; 9]),
            )],
        }
    }
}
