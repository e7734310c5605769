//! Steered cases: the numbers a request makes the course's `random_double` return, what the
//! course's own code makes of them, and how an answer that is not the course's is judged.
//!
//! The course draws every random number through the module-level `RT_utility.random_double`
//! (numpy's global `np.random.uniform`): its `Vec3` static helpers `random_vec3_unit()` (a point
//! of the cube `[-1, 1)^3`, x then y then z, drawn again until `|p|^2 < 1`, divided by its
//! length), `random_vec3_in_unit_disk()` (x then y, until `|p|^2 < 1`) and
//! `random_cosine_hemisphere_on_z()` (`r1`, then `r2`) call it by that name. A steered request
//! gives the values of `random_double` (docs/PROTOCOL.md, "Steering random numbers"), and the
//! expected answer here follows the course's consumption of them, rejection loops included, with
//! the same floating-point operations in the same order.
//!
//! Whether a case is steered comes from the request (every case of a [`super::Body::Steered`]
//! check is), never from the answer. An answer equal to the course's is right. One that is not
//! may come from honest code that draws its numbers another way (numpy directly, another correct
//! sampler): it is judged by what it does, by the [`Behaviour`] of its case (the invariant of
//! the same function's statistical check, in that case's setting), and counts as right only when
//! that statistical check passed too (`docs/weekly-checks.md`, "Steered cases").

use glam::DVec3;

use crate::render::PixelSampler;
use crate::weekly::samplers::{Sample, SamplerCheck};

/// What any answer of a steered case must satisfy when it is not the course's exact one: the
/// answer's `result` object in, what is wrong out.
pub type Behaviour = Box<dyn Fn(&serde_json::Value) -> Result<(), String> + Send + Sync>;

/// A steered case's request seed (derived from the checks' seed, never it): what the code draws
/// past the values given, or instead of them, comes from numpy's generator seeded with it.
pub(crate) fn case_seed(seed: u64, case: &str) -> serde_json::Value {
    serde_json::json!(crate::secret::derive32(seed, &format!("steer/{case}")))
}

/// `random_double(lo, hi)` of the steered value `u`, as the adapter computes it.
pub(crate) fn scaled(u: f64, lo: f64, hi: f64) -> f64 {
    lo + u * (hi - lo)
}

/// The course's `Vec3.unit_vector(p)`: `p / sqrt(x x + y y + z z)`, component by component.
pub(crate) fn course_unit(p: DVec3) -> DVec3 {
    let len = (p.x * p.x + p.y * p.y + p.z * p.z).sqrt();
    DVec3::new(p.x / len, p.y / len, p.z / len)
}

/// What the course's `Vec3.random_vec3_unit()` returns when `random_double` returns `values` in
/// turn, and how many it took; `None` when they run out first.
pub(crate) fn course_unit_vector(values: &[f64]) -> Option<(DVec3, usize)> {
    for (k, t) in values.chunks_exact(3).enumerate() {
        let p = DVec3::new(
            scaled(t[0], -1.0, 1.0),
            scaled(t[1], -1.0, 1.0),
            scaled(t[2], -1.0, 1.0),
        );
        if p.x * p.x + p.y * p.y + p.z * p.z < 1.0 {
            return Some((course_unit(p), 3 * (k + 1)));
        }
    }
    None
}

/// What the course's `Vec3.random_cosine_hemisphere_on_z()` returns for `random_double() = r1,
/// r2`: `phi = 2 pi r1`, `(cos(phi) sqrt(r2), sin(phi) sqrt(r2), sqrt(1 - r2))`.
pub(crate) fn course_cosine_hemisphere(r1: f64, r2: f64) -> DVec3 {
    let phi = 2.0 * std::f64::consts::PI * r1;
    DVec3::new(
        phi.cos() * r2.sqrt(),
        phi.sin() * r2.sqrt(),
        (1.0 - r2).sqrt(),
    )
}

/// The values that make the course's `random_vec3_unit()` take the point `p` of the cube
/// (`(p + 1) / 2`, exact for the dyadic points the fixed cases use).
pub(crate) fn cube_values(p: DVec3) -> Vec<f64> {
    vec![(p.x + 1.0) / 2.0, (p.y + 1.0) / 2.0, (p.z + 1.0) / 2.0]
}

/// Random values for one `random_vec3_unit()`: a triple the course keeps (`|p|^2` in
/// `[0.01, 1)`, so the direction is well away from rounding), preceded by one it rejects
/// (`|p|^2 >= 1`) when `rejected_first`, so the rejection loop is exercised.
pub(crate) fn unit_vector_values(r: &mut PixelSampler, rejected_first: bool) -> Vec<f64> {
    let triple = |r: &mut PixelSampler| [r.next_f64(), r.next_f64(), r.next_f64()];
    let len2 = |t: &[f64; 3]| {
        let p = t.map(|u| scaled(u, -1.0, 1.0));
        p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    };
    let mut out = Vec::new();
    if rejected_first {
        let t = loop {
            let t = triple(r);
            if len2(&t) >= 1.0 {
                break t;
            }
        };
        out.extend(t);
    }
    let t = loop {
        let t = triple(r);
        let l = len2(&t);
        if (0.01..1.0).contains(&l) {
            break t;
        }
    };
    out.extend(t);
    out
}

/// A scattering answer as a sampler's [`Sample`]: origin, direction, attenuation (an absorbed
/// ray, `"scattered": false`, is not one).
pub(crate) fn scatter_sample(answer: &serde_json::Value) -> Result<Sample, String> {
    if answer.get("scattered") == Some(&serde_json::Value::Bool(false)) {
        return Err("it returned no scattered ray (None)".into());
    }
    let mut s = [0.0; 9];
    for (k, key) in ["origin", "direction", "attenuation"].iter().enumerate() {
        let v = crate::weekly::expect::numbers(answer.get(*key), 3)
            .ok_or_else(|| format!("its {key} is not 3 numbers"))?;
        s[3 * k..3 * k + 3].copy_from_slice(&v);
    }
    Ok(s)
}

/// The behaviour of a scattering case: the answer keeps the course's invariant of `check` (the
/// statistical check of the same material, in this case's setting).
pub(crate) fn scatter_behaviour(check: SamplerCheck) -> Behaviour {
    Box::new(move |answer| {
        let s = scatter_sample(answer)?;
        check.course.invariant_holds(&s)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rejection_loop_takes_the_first_triple_inside_the_ball() {
        // (0.5, 0, 0) at once: the unit x axis, 3 values taken.
        assert_eq!(course_unit_vector(&[0.75, 0.5, 0.5]), Some((DVec3::X, 3)));
        // A corner of the cube first (|p|^2 = 2.43 >= 1): rejected, then (0, -0.5, 0).
        let (u, taken) = course_unit_vector(&[0.95, 0.95, 0.05, 0.5, 0.25, 0.5]).unwrap();
        assert_eq!((u, taken), (DVec3::NEG_Y, 6));
        // Out of values.
        assert_eq!(course_unit_vector(&[0.95, 0.95, 0.05]), None);
    }

    #[test]
    fn random_values_give_unit_vectors_and_reject_when_asked() {
        let mut r = PixelSampler::new(1, 2);
        for k in 0..200 {
            let values = unit_vector_values(&mut r, k % 2 == 0);
            assert_eq!(values.len(), if k % 2 == 0 { 6 } else { 3 });
            let (u, taken) = course_unit_vector(&values).unwrap();
            assert_eq!(taken, values.len());
            assert!((u.length() - 1.0).abs() < 1e-15, "{u}");
        }
    }

    #[test]
    fn the_cosine_hemisphere_of_known_values() {
        // r2 = 0: the pole; r1 = 0.5, r2 = 1: (-1, 0, 0) up to the sine of pi.
        assert_eq!(course_cosine_hemisphere(0.3, 0.0), DVec3::Z);
        let d = course_cosine_hemisphere(0.5, 1.0);
        assert!((d - DVec3::NEG_X).length() < 1e-15, "{d}");
        assert_eq!(
            cube_values(DVec3::new(0.5, 0.0, -0.5)),
            vec![0.75, 0.5, 0.25]
        );
    }
}
