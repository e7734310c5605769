//! A vector's expected answer in words ([`expected_in_words`]), and a Python snippet that
//! reproduces it against the course's API ([`python_repro`]): what a failure shows so that its
//! author can run it again.

use crate::oracle::vectors::{Case, Class, Expect, ShapeSpec};

/// A float as Rust prints it (shortest round trip), `inf`, `-inf` or `nan`.
fn num(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:?}")
    }
}

/// How an expected answer is written: its numbers, its booleans, and what follows a miss and a
/// normal (the words of any language, or Python's).
struct Dialect {
    number: fn(f64) -> String,
    boolean: fn(bool) -> &'static str,
    miss: &'static str,
    normal_note: &'static str,
}

/// The expected answer of a vector in words, for any language.
pub fn expected_in_words(e: &Expect) -> String {
    expected_as(
        e,
        &Dialect {
            number: num,
            boolean: |b| if b { "true" } else { "false" },
            miss: "a miss",
            normal_note: " (unit, facing the ray)",
        },
    )
}

/// The expected answer of a vector written in `dialect`.
fn expected_as(e: &Expect, dialect: &Dialect) -> String {
    let number = dialect.number;
    match e.class {
        Class::Miss => dialect.miss.to_string(),
        Class::Hit => {
            let mut s = String::from("a hit");
            if let Some(t) = e.t {
                s.push_str(&format!(" at t = {}", number(t)));
                if let Some(tol) = e.t_tol {
                    s.push_str(&format!(" (+- {tol:.1e})"));
                }
            }
            if let Some(n) = e.normal {
                s.push_str(&format!(
                    ", normal ({}, {}, {}){}",
                    number(n[0]),
                    number(n[1]),
                    number(n[2]),
                    dialect.normal_note
                ));
            }
            if let Some(f) = e.front_face {
                s.push_str(&format!(", front_face {}", (dialect.boolean)(f)));
            }
            s
        }
        // The exact answer, which rounding may turn either way: a hit when it has a `t`.
        Class::Ambiguous => {
            let mut exact = e.clone();
            exact.class = if e.t.is_some() {
                Class::Hit
            } else {
                Class::Miss
            };
            format!(
                "exactly {}, where rounding decides (not scored)",
                expected_as(&exact, dialect)
            )
        }
        Class::Any => "anything (not scored)".to_string(),
    }
}

/// A float as a Python literal that reads back to the same bits.
fn py(x: f64) -> String {
    if x.is_nan() {
        "float('nan')".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "float('inf')".into()
        } else {
            "float('-inf')".into()
        }
    } else {
        format!("{x:?}")
    }
}

fn py3(v: [f64; 3]) -> String {
    format!("Vec3({}, {}, {})", py(v[0]), py(v[1]), py(v[2]))
}

/// A Python snippet that reproduces `case` against the course's API: builds the object with
/// the course's constructor, calls `intersect` and prints what it got and what it should get.
pub fn python_repro(case: &Case) -> String {
    let (class_name, ctor) = match case.shape {
        ShapeSpec::Sphere { center, radius } => (
            "Sphere",
            format!("Sphere({}, {}, None)", py3(center), py(radius)),
        ),
        ShapeSpec::Quad { q, u, v } => (
            "Quad",
            format!("Quad({}, {}, {}, None)", py3(q), py3(u), py3(v)),
        ),
        ShapeSpec::Triangle { a, b, c } => (
            "Triangle",
            format!("Triangle({}, {}, {})", py3(a), py3(b), py3(c)),
        ),
    };
    let expected = expected_as(
        &case.expect,
        &Dialect {
            number: py,
            boolean: |b| if b { "True" } else { "False" },
            miss: "a miss (None)",
            normal_note: "",
        },
    );
    format!(
        "from RT_utility import Vec3, Interval\n\
         from RT_ray import Ray\n\
         from RT_object import {class_name}\n\
         obj = {ctor}\n\
         ray = Ray({}, {})\n\
         hit = obj.intersect(ray, Interval({}, {}))\n\
         print(None if hit is None else (hit.getT(), hit.getNormal().e, hit.front_face))\n\
         # expected: {expected}\n",
        py3(case.ray.origin),
        py3(case.ray.direction),
        py(case.interval[0]),
        py(case.interval[1]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn python_literals_read_back_exactly() {
        assert_eq!(py(0.1), "0.1");
        assert_eq!(py(4.0), "4.0");
        assert_eq!(py(f64::MAX), "1.7976931348623157e308");
        assert_eq!(py(1e-6), "1e-6");
        assert_eq!(py(f64::NEG_INFINITY), "float('-inf')");
    }
}
