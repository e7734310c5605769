//! Python reproductions of the requests, written with the course's modules and short names, so
//! a student can paste one into a Python started in the submission folder.
//!
//! They follow the course's real code (weeks 5 to 10): `reflect`, `refract`, `schlick` and
//! `halfvector` are `RT_material`'s, `Diffuse_light` is `RT_light`'s, the random helpers are
//! static methods of `RT_utility.Vec3`. Each ends with one `print` of what the check compares:
//! the value itself when the check compares one field of the answer, else the fields as
//! separate arguments in the answer's order or a dict keyed by the answer's field names (so a
//! test can run every reproduction in the course's folder and compare what it prints with the
//! reference's answer).

use glam::DVec3;

/// The import lines every reproduction starts with.
pub(crate) const IMPORTS: &str =
    "import math\nimport RT_utility as rtu, RT_ray as rtr, RT_object as rto, RT_material as rtm";

/// A number as Python reads it (shortest round trip; `math.inf`, `math.nan`).
pub(crate) fn f(x: f64) -> String {
    if x.is_nan() {
        "math.nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "math.inf" } else { "-math.inf" }.into()
    } else {
        format!("{x:?}")
    }
}

/// `rtu.Vec3(x, y, z)`.
pub(crate) fn vec(v: DVec3) -> String {
    format!("rtu.Vec3({}, {}, {})", f(v.x), f(v.y), f(v.z))
}

/// `rtu.Color(r, g, b)`.
pub(crate) fn color(v: DVec3) -> String {
    format!("rtu.Color({}, {}, {})", f(v.x), f(v.y), f(v.z))
}

/// `rtr.Ray(origin, direction)` (with the time when it is not 0).
pub(crate) fn ray(origin: DVec3, direction: DVec3, time: f64) -> String {
    if time == 0.0 {
        format!("rtr.Ray({}, {})", vec(origin), vec(direction))
    } else {
        format!("rtr.Ray({}, {}, {})", vec(origin), vec(direction), f(time))
    }
}

/// The lines that make `rtu.random_double` return `values` in turn (scaled to its range).
pub(crate) fn random_doubles(values: &[f64]) -> String {
    let list: Vec<String> = values.iter().map(|&u| f(u)).collect();
    format!(
        "_u = iter([{}])\nrtu.random_double = lambda min=0.0, max=1.0: min + next(_u) * (max - min)",
        list.join(", ")
    )
}

/// The line that prints what a scattering `s` gave: its ray's origin and direction and its
/// attenuation, keyed as the answer's fields.
pub(crate) const PRINT_SCATTERED: &str = "print({'origin': s.scattered_ray.getOrigin().e, 'direction': s.scattered_ray.getDirection().e, 'attenuation': s.attenuation_color.e})";

/// A hit record as the course's intersect makes one, in a variable `hit`.
pub(crate) fn hit(point: DVec3, outward: DVec3, ray_var: &str, material: &str) -> String {
    format!(
        "hit = rtu.Hitinfo({}, {}, 1.0, {material})\nhit.set_face_normal({ray_var}, {})",
        vec(point),
        vec(outward),
        vec(outward)
    )
}

/// A whole reproduction: the imports, `body`, and what the course's code answers.
pub(crate) fn script(body: &str, course_answer: &str) -> String {
    format!("{IMPORTS}\n{body}\n# the course's code gives {course_answer}")
}

/// `[x, y, z]` as the course's answer is shown.
pub(crate) fn list(v: DVec3) -> String {
    format!("[{}, {}, {}]", f(v.x), f(v.y), f(v.z))
}
