//! Entry points of the fuzz targets (`fuzz/fuzz_targets/*.rs` call these), so that plain
//! `cargo test` can replay their corpora through the same code.
//!
//! Each shape target reads raw `f64` bit patterns (8 bytes each, little endian; missing bytes
//! are zero) for the shape, the ray and the interval, and checks: the reference tracer and the
//! classifier do not panic, every reference hit has a finite `t` inside the interval, and on
//! every definite case the reference's decision equals the exact one, with `t` within `t_tol`.

use super::classify::analyse;
use super::generate::unflatten;
use super::vectors::{Case, Class, ShapeKind};
use crate::geometry::{Interval, Shape};

/// A property violation found by a fuzz target.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Violation(pub String);

fn numbers(bytes: &[u8], n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let mut b = [0u8; 8];
            for (j, x) in b.iter_mut().enumerate() {
                *x = bytes.get(8 * i + j).copied().unwrap_or(0);
            }
            f64::from_le_bytes(b)
        })
        .collect()
}

/// Checks one case of `kind` built from raw bytes.
pub fn check_shape_bytes(kind: ShapeKind, bytes: &[u8]) -> Result<(), Violation> {
    let n = match kind {
        ShapeKind::Sphere => 4 + 8,
        _ => 9 + 8,
    };
    let x = numbers(bytes, n);
    let c = unflatten(kind, &x, vec![]);
    let interval = Interval::new(c.interval[0], c.interval[1]);
    let hit = c.shape.object().intersect(&c.ray.ray(), interval);
    let a = analyse(&c.shape, &c.ray, c.interval);
    let case = || {
        format!(
            "{kind} case {:?}",
            x.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        )
    };
    if let Some(h) = &hit {
        if !h.t.is_finite() {
            return Err(Violation(format!(
                "{}: the reference hit at t = {}",
                case(),
                h.t
            )));
        }
    }
    match a.class {
        Class::Hit => {
            let Some(h) = hit else {
                return Err(Violation(format!(
                    "{}: definite hit, the reference misses",
                    case()
                )));
            };
            let (t, tol) = (
                a.hit.map(|e| e.t).unwrap_or(f64::NAN),
                a.t_tol.unwrap_or(0.0),
            );
            if (h.t - t).abs().is_nan() || (h.t - t).abs() > tol {
                return Err(Violation(format!(
                    "{}: the reference's t = {} is not within {tol:e} of the exact {t}",
                    case(),
                    h.t
                )));
            }
        }
        Class::Miss => {
            if let Some(h) = hit {
                return Err(Violation(format!(
                    "{}: definite miss, the reference hits at t = {}",
                    case(),
                    h.t
                )));
            }
        }
        Class::Ambiguous | Class::Any => {}
    }
    Ok(())
}

/// The sphere target.
pub fn check_sphere_bytes(bytes: &[u8]) -> Result<(), Violation> {
    check_shape_bytes(ShapeKind::Sphere, bytes)
}

/// The quad target.
pub fn check_quad_bytes(bytes: &[u8]) -> Result<(), Violation> {
    check_shape_bytes(ShapeKind::Quad, bytes)
}

/// The triangle target.
pub fn check_triangle_bytes(bytes: &[u8]) -> Result<(), Violation> {
    check_shape_bytes(ShapeKind::Triangle, bytes)
}

/// The scene-file target: any text either parses into a scene that validates and builds, or
/// is refused with an error; never a panic.
pub fn check_scene_bytes(bytes: &[u8]) -> Result<(), Violation> {
    let text = String::from_utf8_lossy(bytes);
    if let Ok(desc) = crate::scene::SceneDescription::from_toml(&text, "fuzz.toml") {
        if desc.validate("fuzz.toml").is_ok() {
            let _ = desc.scene();
            let _ = desc.camera(Some(4));
        }
    }
    Ok(())
}

/// The vector-line target: any line either is refused, or parses into a case that writes back
/// to a line parsing to the same case, bit for bit.
pub fn check_vector_line_bytes(bytes: &[u8]) -> Result<(), Violation> {
    let text = String::from_utf8_lossy(bytes);
    if let Ok(case) = Case::from_json_line(&text) {
        let line = case.to_json_line();
        let back = Case::from_json_line(&line)
            .map_err(|e| Violation(format!("a written line does not parse: {e}: {line}")))?;
        let bits = |c: &Case| {
            let mut v: Vec<u64> = c.shape.numbers().iter().map(|x| x.to_bits()).collect();
            v.extend(
                c.ray
                    .origin
                    .iter()
                    .chain(&c.ray.direction)
                    .chain(&c.interval)
                    .map(|x| x.to_bits()),
            );
            v
        };
        // NaN payloads are not kept (the format has one "nan").
        let norm = |v: Vec<u64>| -> Vec<u64> {
            v.into_iter()
                .map(|b| if f64::from_bits(b).is_nan() { 0 } else { b })
                .collect()
        };
        if norm(bits(&case)) != norm(bits(&back))
            || case.id != back.id
            || case.expect.class != back.expect.class
        {
            return Err(Violation(format!("the line does not round-trip: {line}")));
        }
    }
    Ok(())
}

/// The body of a fuzz target.
pub type Target = fn(&[u8]) -> Result<(), Violation>;

/// The function of each fuzz target, by target name.
pub fn target(name: &str) -> Option<Target> {
    Some(match name {
        "sphere" => check_sphere_bytes,
        "quad" => check_quad_bytes,
        "triangle" => check_triangle_bytes,
        "scene_file" => check_scene_bytes,
        "vector_line" => check_vector_line_bytes,
        _ => return None,
    })
}

/// The names of the fuzz targets.
pub const TARGETS: [&str; 5] = ["sphere", "quad", "triangle", "scene_file", "vector_line"];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::generate::Stream;

    /// A cheap fuzzer in the test suite: inputs drawn from special values and random bits.
    #[test]
    fn special_values_never_break_the_shape_properties() {
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            2.0,
            f64::MAX,
            -f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e300,
            -1e300,
            1e-300,
            1e154,
            1e-160,
        ];
        let mut r = Stream::new(5, "fuzz-special");
        for i in 0..60_000 {
            let kind = [ShapeKind::Sphere, ShapeKind::Quad, ShapeKind::Triangle][i % 3];
            let mut bytes = Vec::new();
            for _ in 0..17 {
                let x = match r.int(0, 3) {
                    0 => special[r.int(0, special.len() as i64 - 1) as usize],
                    1 => f64::from_bits(r.bits()),
                    _ => r.int(-4, 4) as f64,
                };
                bytes.extend(x.to_le_bytes());
            }
            if let Err(v) = check_shape_bytes(kind, &bytes) {
                panic!("{v}");
            }
        }
    }
}
