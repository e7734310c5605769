//! The checks of the course's direction samplers: the unit sphere, the cosine hemisphere, the
//! unit disk.

use glam::DVec3;

use super::*;

fn sphere_hypothesis(
    name: &'static str,
    standing: Standing,
    says: &str,
    probs: Probs,
    draw: fn(&mut PixelSampler) -> DVec3,
) -> Hypothesis {
    Hypothesis::new(
        name,
        standing,
        says,
        Box::new(|s| {
            finite(s)?;
            unit_length(v3(s, 0), "the vector")
        }),
        (SPHERE_CELLS, Box::new(|s| sphere_cell(v3(s, 0)))),
        probs,
        Box::new(move |r| sample_of(draw(r), DVec3::ZERO, DVec3::ZERO)),
    )
}

impl SamplerCheck {
    /// `random_vec3_unit()`: unit vectors, uniform on the sphere.
    pub fn unit_sphere() -> Self {
        let ball = Hypothesis::new(
            "unit_vector_not_normalised",
            Standing::Mistake,
            "a uniform point inside the unit ball, not on the sphere (not normalised)",
            Box::new(|s| {
                finite(s)?;
                let l = v3(s, 0).length();
                if l <= 1.0 + 1e-9 {
                    Ok(())
                } else {
                    Err(format!("length {l:?} > 1"))
                }
            }),
            (
                10,
                Box::new(|s| ((v3(s, 0).length().powi(3) * 10.0) as usize).min(9)),
            ),
            Probs::Equal,
            Box::new(|r| sample_of(mistakes::in_ball(r), DVec3::ZERO, DVec3::ZERO)),
        );
        SamplerCheck {
            kind: SamplerKind::UnitSphere,
            samples: UNIT_SPHERE_SAMPLES,
            course: sphere_hypothesis(
                "course",
                Standing::Course,
                "a unit vector, uniform on the sphere",
                Probs::Equal,
                mistakes::unit_vector,
            ),
            mistakes: vec![
                ball,
                sphere_hypothesis(
                    "unit_vector_from_cube",
                    Standing::Mistake,
                    "a point of the cube normalised without rejecting those outside the ball (the cube's corners are over-represented)",
                    Probs::Simulated(OnceLock::new()),
                    mistakes::unit_vector_from_cube,
                ),
                sphere_hypothesis(
                    "unit_vector_uniform_angles",
                    Standing::Mistake,
                    "the polar angle drawn uniformly (the poles are over-represented)",
                    Probs::Simulated(OnceLock::new()),
                    mistakes::unit_vector_uniform_angles,
                ),
            ],
        }
    }

    /// `random_cosine_hemisphere_on_z()`: unit vectors about `z` with density `cos / pi`.
    pub fn cosine_hemisphere() -> Self {
        let hemisphere =
            |name, standing, says: &str, probs, draw: fn(&mut PixelSampler) -> DVec3| {
                Hypothesis::new(
                    name,
                    standing,
                    says,
                    Box::new(|s| {
                        finite(s)?;
                        let d = v3(s, 0);
                        unit_length(d, "the direction")?;
                        if d.z >= -1e-12 {
                            Ok(())
                        } else {
                            Err(format!(
                                "the direction {} points below the xy plane",
                                fmt(d)
                            ))
                        }
                    }),
                    (LOBE_CELLS, Box::new(|s| lobe_cell(v3(s, 0)))),
                    probs,
                    Box::new(move |r| sample_of(draw(r), DVec3::ZERO, DVec3::ZERO)),
                )
            };
        SamplerCheck {
            kind: SamplerKind::CosineHemisphere,
            samples: HEMISPHERE_SAMPLES,
            course: hemisphere(
                "course",
                Standing::Course,
                "a unit vector of the upper hemisphere with density cos(theta) / pi",
                Probs::Equal,
                mistakes::cosine_hemisphere,
            ),
            mistakes: vec![hemisphere(
                "hemisphere_instead_of_cosine_lobe",
                Standing::Mistake,
                "the hemisphere sampled uniformly (z = r2) instead of the cosine lobe (z = sqrt(1 - r2))",
                Probs::Simulated(OnceLock::new()),
                mistakes::uniform_hemisphere,
            )],
        }
    }

    /// `random_in_unit_disk()`: points of the open unit disk of the xy plane, uniform.
    pub fn unit_disk() -> Self {
        let disk_invariant = |s: &Sample| {
            finite(s)?;
            let p = v3(s, 0);
            if p.z.abs() > 1e-12 {
                return Err(format!("the point {} is not in the xy plane", fmt(p)));
            }
            if p.x * p.x + p.y * p.y <= 1.0 + 1e-12 {
                Ok(())
            } else {
                Err(format!("the point {} lies outside the unit disk", fmt(p)))
            }
        };
        SamplerCheck {
            kind: SamplerKind::UnitDisk,
            samples: DISK_SAMPLES,
            course: Hypothesis::new(
                "course",
                Standing::Course,
                "a point of the unit disk, uniform",
                Box::new(disk_invariant),
                (DISK_CELLS, Box::new(|s| disk_cell(s[0], s[1]))),
                Probs::Equal,
                Box::new(|r| sample_of(mistakes::in_disk(r), DVec3::ZERO, DVec3::ZERO)),
            ),
            mistakes: vec![
                square_hypothesis(|r| sample_of(mistakes::in_square(r), DVec3::ZERO, DVec3::ZERO)),
                Hypothesis::new(
                    "disk_radius_uniform",
                    Standing::Mistake,
                    "polar coordinates with a uniform radius (the centre is over-represented; the radius wants a square root)",
                    Box::new(disk_invariant),
                    (DISK_CELLS, Box::new(|s| disk_cell(s[0], s[1]))),
                    Probs::Simulated(OnceLock::new()),
                    Box::new(|r| {
                        sample_of(mistakes::disk_radius_uniform(r), DVec3::ZERO, DVec3::ZERO)
                    }),
                ),
            ],
        }
    }
}
