//! The checks of the materials' scattering: the Lambertian (week 5's `n + u`, week 9's cosine
//! lobe), the metal's fuzz, the dielectric's choice between reflection and refraction.

use glam::DVec3;

use super::*;

/// A Lambertian's scattering at `point` with unit normal `normal` and `albedo`.
struct Surface {
    point: DVec3,
    normal: DVec3,
    albedo: DVec3,
}

impl Surface {
    /// A unit direction of the hemisphere about the normal, in its lobe cells.
    fn lobe(
        &self,
        name: &'static str,
        standing: Standing,
        says: &str,
        probs: Probs,
        draw: impl Fn(&mut PixelSampler) -> DVec3 + Send + Sync + 'static,
        course_checks: bool,
    ) -> Hypothesis {
        let (p, n, a) = (self.point, self.normal, self.albedo);
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                if course_checks {
                    origin_and_attenuation(s, p, a)?;
                }
                let d = v3(s, 1);
                unit_length(d, "the scattered direction")?;
                if d.dot(n) >= -1e-12 {
                    Ok(())
                } else {
                    Err(format!(
                        "the scattered direction {} points into the surface (normal {})",
                        fmt(d),
                        fmt(n)
                    ))
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1)))),
            ),
            probs,
            Box::new(move |r| sample_of(p, draw(r), a)),
        )
    }
}

impl SamplerCheck {
    /// Week 5's `Lambertian.scattering` at `point` (unit normal `normal`, `albedo`): the
    /// course's `n + u`, not normalised, so `|d|^2 = 2 d . n` and `d / |d|` follows the cosine
    /// lobe about `n`.
    pub fn lambertian_n_plus_u(point: DVec3, normal: DVec3, albedo: DVec3) -> Self {
        let surface = Surface {
            point,
            normal,
            albedo,
        };
        let (p, n, a) = (point, normal, albedo);
        let course = Hypothesis::new(
            "course",
            Standing::Course,
            "n + u for a uniform unit vector u, not normalised",
            Box::new(move |s| {
                finite(s)?;
                origin_and_attenuation(s, p, a)?;
                let d = v3(s, 1);
                let (l2, dn) = (d.length_squared(), 2.0 * d.dot(n));
                if (l2 - dn).abs() <= tol(l2) {
                    Ok(())
                } else {
                    Err(format!(
                        "the scattered direction {} is not n + u for a unit u: |d|^2 = {l2:?}, 2 d . n = {dn:?} (normal {})",
                        fmt(d),
                        fmt(n)
                    ))
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1).normalize_or_zero()))),
            ),
            Probs::Equal,
            Box::new(move |r| sample_of(p, n + mistakes::unit_vector(r), a)),
        );
        let normalised = surface.lobe(
            "n_plus_u_normalised",
            Standing::Mistake,
            "n + u normalised (the course leaves it as it is: its length 2 cos(theta) weighs week 8's cosine)",
            Probs::Equal,
            move |r| (n + mistakes::unit_vector(r)).normalize(),
            false,
        );
        let hemisphere = surface.lobe(
            "hemisphere_instead_of_cosine_lobe",
            Standing::Mistake,
            "a uniform unit vector flipped to the normal's side: the hemisphere uniformly instead of the cosine lobe",
            Probs::Simulated(OnceLock::new()),
            move |r| mistakes::about(n, mistakes::uniform_hemisphere(r)),
            false,
        );
        SamplerCheck {
            kind: SamplerKind::LambertianNPlusU,
            samples: LAMBERTIAN_SAMPLES,
            course,
            mistakes: vec![normalised, hemisphere],
        }
    }

    /// Week 9's `Lambertian.scattering`: a unit direction with density `cos / pi` about `n`.
    pub fn lambertian_cosine(point: DVec3, normal: DVec3, albedo: DVec3) -> Self {
        let surface = Surface {
            point,
            normal,
            albedo,
        };
        let (p, n, a) = (point, normal, albedo);
        let course = surface.lobe(
            "course",
            Standing::Course,
            "a unit direction with density cos(theta) / pi about the normal",
            Probs::Equal,
            move |r| mistakes::about(n, mistakes::cosine_hemisphere(r)),
            true,
        );
        let hemisphere = surface.lobe(
            "hemisphere_instead_of_cosine_lobe",
            Standing::Mistake,
            "the hemisphere about the normal sampled uniformly instead of the cosine lobe",
            Probs::Simulated(OnceLock::new()),
            move |r| mistakes::about(n, mistakes::uniform_hemisphere(r)),
            false,
        );
        let wrong_axis = Hypothesis::new(
            "lobe_around_wrong_axis",
            Standing::Mistake,
            "the cosine lobe lies about a tangent instead of the normal (ONB.local mixes up its axes): half the directions point into the surface",
            Box::new(|s| {
                finite(s)?;
                unit_length(v3(s, 1), "the scattered direction")
            }),
            (
                10,
                Box::new(move |s| (((v3(s, 1).dot(n) + 1.0) * 5.0) as usize).min(9)),
            ),
            Probs::Simulated(OnceLock::new()),
            Box::new(move |r| {
                let c = mistakes::cosine_hemisphere(r);
                sample_of(p, mistakes::about(n, DVec3::new(c.z, c.y, c.x)), a)
            }),
        );
        let kept_week5 = Hypothesis::new(
            "n_plus_u_kept",
            Standing::Mistake,
            "week 5's n + u, not normalised, instead of the cosine lobe through the ONB",
            Box::new(move |s| {
                finite(s)?;
                let d = v3(s, 1);
                let (l2, dn) = (d.length_squared(), 2.0 * d.dot(n));
                if (l2 - dn).abs() <= tol(l2) && (d.length() - 1.0).abs() > 1e-6 {
                    Ok(())
                } else {
                    Err("not n + u".into())
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1).normalize_or_zero()))),
            ),
            Probs::Equal,
            Box::new(move |r| sample_of(p, n + mistakes::unit_vector(r), a)),
        );
        SamplerCheck {
            kind: SamplerKind::LambertianCosine,
            samples: LAMBERTIAN_SAMPLES,
            course,
            mistakes: vec![hemisphere, wrong_axis, kept_week5],
        }
    }
}

/// A metal's scattering: the hit, the mirror direction of the unit incoming direction, the
/// roughness as the course clamps it (at most 1) and as the scene gave it, and the mirror
/// direction of the raw incoming direction.
#[derive(Clone, Copy, Debug)]
pub struct MetalSetting {
    /// The hit point.
    pub point: DVec3,
    /// The unit normal facing the incoming ray.
    pub normal: DVec3,
    /// The albedo.
    pub albedo: DVec3,
    /// `reflect(unit(d), n)`.
    pub mirror: DVec3,
    /// `reflect(d, n)` of the raw direction.
    pub raw_mirror: DVec3,
    /// The roughness the course uses, `min(roughness, 1)`.
    pub roughness: f64,
    /// The roughness as given to the constructor.
    pub given_roughness: f64,
}

impl MetalSetting {
    fn fuzz(
        &self,
        name: &'static str,
        says: &str,
        mirror: DVec3,
        radius: f64,
        course: bool,
    ) -> Hypothesis {
        let m = *self;
        Hypothesis::new(
            name,
            if course {
                Standing::Course
            } else {
                Standing::Mistake
            },
            says,
            Box::new(move |s| {
                finite(s)?;
                if course {
                    let o = v3(s, 0);
                    if (o - m.point).abs().max_element() > tol(m.point.abs().max_element()) {
                        return Err(format!(
                            "the scattered ray starts at {}, not at the hit point {}",
                            fmt(o),
                            fmt(m.point)
                        ));
                    }
                }
                let d = v3(s, 1);
                let off = (d - mirror).length();
                if (off - radius).abs() > tol(radius) {
                    return Err(format!(
                        "the scattered direction {} lies {off:?} from the mirror direction {}, not the roughness {radius:?}",
                        fmt(d),
                        fmt(mirror)
                    ));
                }
                if course {
                    // The attenuation: the albedo, or zero at or below 1e-8 (a sample within
                    // rounding of the threshold is not judged on it).
                    let dn = d.dot(m.normal);
                    let a = v3(s, 2);
                    if (dn - 1e-8).abs() > 1e-12 {
                        let want = if dn <= 1e-8 { DVec3::ZERO } else { m.albedo };
                        if (a - want).abs().max_element() > 1e-12 {
                            return Err(format!(
                                "the attenuation is {} where d . n = {dn:?}: the course's is {}",
                                fmt(a),
                                fmt(want)
                            ));
                        }
                    }
                }
                Ok(())
            }),
            (
                SPHERE_CELLS,
                Box::new(move |s| {
                    sphere_cell(
                        ((v3(s, 1) - mirror) / radius.max(f64::MIN_POSITIVE)).normalize_or_zero(),
                    )
                }),
            ),
            Probs::Equal,
            Box::new(move |r| {
                let d = mirror + radius * mistakes::unit_vector(r);
                let a = if d.dot(m.normal) <= 1e-8 {
                    DVec3::ZERO
                } else {
                    m.albedo
                };
                sample_of(m.point, d, a)
            }),
        )
    }
}

impl SamplerCheck {
    /// `Metal.scattering`: `reflect(unit(d), n) + roughness u` for a uniform unit `u`.
    pub fn metal(setting: MetalSetting) -> Self {
        let m = setting;
        let mut mistakes = vec![
            Hypothesis::new(
                "metal_roughness_ignored",
                Standing::Mistake,
                "the mirror direction alone: the roughness times a random unit vector is not added",
                Box::new(move |s| {
                    finite(s)?;
                    if (v3(s, 1) - m.mirror).length() <= tol(1.0) {
                        Ok(())
                    } else {
                        Err("not the mirror direction".into())
                    }
                }),
                (1, Box::new(|_| 0)),
                Probs::Equal,
                Box::new(move |_| sample_of(m.point, m.mirror, m.albedo)),
            ),
            Hypothesis::new(
                "metal_fuzz_in_ball",
                Standing::Mistake,
                "the roughness times a point inside the unit ball (the book's first fuzz) instead of a unit vector",
                Box::new(move |s| {
                    finite(s)?;
                    if (v3(s, 1) - m.mirror).length() < m.roughness + tol(m.roughness) {
                        Ok(())
                    } else {
                        Err("outside the ball".into())
                    }
                }),
                (
                    10,
                    Box::new(move |s| {
                        (((v3(s, 1) - m.mirror).length() / m.roughness).powi(3) * 10.0) as usize
                    }),
                ),
                Probs::Equal,
                Box::new(move |r| {
                    sample_of(
                        m.point,
                        m.mirror + m.roughness * mistakes::in_ball(r),
                        m.albedo,
                    )
                }),
            ),
        ];
        if (m.raw_mirror - m.mirror).length() > 1e-6 {
            mistakes.push(m.fuzz(
                "metal_reflects_raw_direction",
                "the raw incoming direction reflected (the course reflects the unit direction)",
                m.raw_mirror,
                m.roughness,
                false,
            ));
        }
        if m.given_roughness > m.roughness {
            mistakes.push(m.fuzz(
                "metal_roughness_not_clamped",
                "the roughness used as given, above 1 (the course clamps it to 1)",
                m.mirror,
                m.given_roughness,
                false,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::MetalFuzz,
            samples: METAL_SAMPLES,
            course: m.fuzz(
                "course",
                "reflect(unit(d), n) + roughness u, u uniform on the unit sphere",
                m.mirror,
                m.roughness,
                true,
            ),
            mistakes,
        }
    }
}

/// A dielectric's choice at one hit: the two directions and the course's probability of
/// reflecting, with the probabilities the mistakes give.
#[derive(Clone, Copy, Debug)]
pub struct DielectricSetting {
    /// The hit point.
    pub point: DVec3,
    /// The albedo.
    pub albedo: DVec3,
    /// The reflected direction.
    pub reflected: DVec3,
    /// The refracted direction (`None` under total internal reflection).
    pub refracted: Option<DVec3>,
    /// The course's probability of reflecting: 1 under total internal reflection, else
    /// `schlick(cos, ratio)`.
    pub p_reflect: f64,
    /// The probability when Schlick is fed the sine instead of the cosine.
    pub p_wrong_cosine: f64,
}

impl DielectricSetting {
    fn hypothesis(&self, name: &'static str, standing: Standing, says: &str, p: f64) -> Hypothesis {
        let m = *self;
        let course = standing == Standing::Course;
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                if course {
                    origin_and_attenuation(s, m.point, m.albedo)?;
                }
                let d = v3(s, 1);
                let near = |e: DVec3| (d - e).abs().max_element() <= 1e-9;
                if near(m.reflected) || m.refracted.is_some_and(near) {
                    Ok(())
                } else {
                    Err(match m.refracted {
                        Some(t) => format!(
                            "the scattered direction {} is neither the reflected {} nor the refracted {}",
                            fmt(d),
                            fmt(m.reflected),
                            fmt(t)
                        ),
                        None => format!(
                            "the scattered direction {} is not the reflected {} (total internal reflection)",
                            fmt(d),
                            fmt(m.reflected)
                        ),
                    })
                }
            }),
            (
                2,
                Box::new(move |s| usize::from((v3(s, 1) - m.reflected).abs().max_element() > 1e-9)),
            ),
            Probs::Given(vec![p, 1.0 - p]),
            Box::new(move |r| {
                let d = match m.refracted {
                    Some(t) if r.next_f64() >= p => t,
                    _ => m.reflected,
                };
                sample_of(m.point, d, m.albedo)
            }),
        )
    }
}

impl SamplerCheck {
    /// `Dielectric.scattering`'s choice: reflect with the course's probability, else refract.
    pub fn dielectric(setting: DielectricSetting) -> Self {
        let m = setting;
        let mut mistakes = vec![m.hypothesis(
            "schlick_fraction_inverted",
            Standing::Mistake,
            "always reflects: Schlick's r0 = ((1 + x) / (1 - x))^2 is above 1",
            1.0,
        )];
        if (m.p_wrong_cosine - m.p_reflect).abs() > 1e-6 {
            mistakes.push(m.hypothesis(
                "schlick_wrong_cosine",
                Standing::Mistake,
                "reflects with Schlick's value of the sine instead of the cosine",
                m.p_wrong_cosine,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::DielectricChoice,
            samples: DIELECTRIC_SAMPLES,
            course: m.hypothesis(
                "course",
                Standing::Course,
                "reflects with probability schlick(cos, ratio) (always under total internal reflection), else refracts",
                m.p_reflect,
            ),
            mistakes,
        }
    }
}
