//! Week 7's surfaces: `Sphere.get_uv`, the quad's `(u, v)`, the three textures' `tex_value` and
//! the textured Lambertian's attenuation.
//!
//! Decisions: the checker's cells (`floor(x / s)`) and the image's texel (`int(u W)`) are
//! within rounding of an edge when `x / s` or `u W` is within a few ulps of an integer; those
//! cases are not scored. The course's `ImageTexture` raises `IndexError` at `u = 1` or `v = 1`
//! (after clamping too) and `get_uv` raises `ValueError` when rounding puts `|n.y|` above 1:
//! those inputs are asked, reported, and never scored against the student.

use glam::DVec3;
use serde_json::json;

use super::optics::HitInput;
use super::{Body, CASE_TIMEOUT, Case, FunctionCheck, Variant, jnum, jvec, py, stream, week};
use crate::geometry::{Interval, Quad, Ray, Shape};
use crate::render::sphere_uv;
use crate::scene::{Profile, Texture, TextureImage};
use crate::weekly::expect::{Class, Expected, Want};
use crate::weekly::samplers::Standing;
use crate::weekly::samplers::mistakes;

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![
        sphere_uv_check(seed),
        quad_uv_check(seed),
        solid_check(),
        checker_check(seed),
        image_check(seed),
        textured_check(seed),
    ]
}

fn uv_want(uv: (f64, f64)) -> Expected {
    Expected::one(
        "uv",
        Want::Pair {
            value: [uv.0, uv.1],
            tol: 1e-12,
        },
    )
}

fn sphere_uv_check(seed: u64) -> FunctionCheck {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let mut normals = vec![
        DVec3::X,
        DVec3::Z,
        -DVec3::Z,
        -DVec3::Y,
        DVec3::Y,
        DVec3::new(s, 0.0, -s),
        DVec3::new(0.6, 0.8, 0.0),
        -DVec3::X,
        DVec3::new(-1.0, 0.0, -0.0),
        DVec3::new(0.0, 1.000_000_000_000_000_2, 0.0),
    ];
    let mut r = stream(seed, "sphere-uv");
    for _ in 0..8 {
        normals.push(mistakes::unit_vector(&mut r));
    }
    let mut cases = Vec::new();
    let (mut swapped, mut no_offset, mut flipped) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &n) in normals.iter().enumerate() {
        let uv = sphere_uv(n);
        let class = if n.y.abs() > 1.0 {
            Class::CourseFails(
                "|n.y| > 1: the course's acos raises ValueError (rounding at a pole)".into(),
            )
        } else if n.z == 0.0 && n.x < 0.0 {
            Class::Ambiguous(
                "on the seam (n.z = 0, n.x < 0): the sign of zero decides u = 0 or 1".into(),
            )
        } else {
            Class::Definite
        };
        cases.push(Case {
            id: format!("sphere-uv-{k:04}"),
            request: json!({"op": "sphere_uv", "normal": jvec(n)}),
            expect: uv_want(uv),
            class,
            input: format!("normal = {}", py::list(n)),
            repro: py::script(
                &format!(
                    "print(rto.Sphere(rtu.Vec3(0, 0, 0), 1.0).get_uv({}))",
                    py::vec(n)
                ),
                &format!("({}, {})", py::f(uv.0), py::f(uv.1)),
            ),
        });
        swapped.push(Some(uv_want((uv.1, uv.0))));
        no_offset.push(Some(uv_want((uv.0 - 0.5, uv.1))));
        flipped.push(Some(uv_want((uv.0, 1.0 - uv.1))));
    }
    FunctionCheck {
        id: "sphere-uv",
        function: "RT_object.Sphere.get_uv(normal)",
        week: week(7),
        given: false,
        op: "sphere_uv",
        tolerance: "u and v within 1e-12; the seam (n.z = 0, n.x < 0) is not scored, nor |n.y| > 1 (the course's acos raises)",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "uv_swapped",
                    says: "Sphere.get_uv returns (v, u)",
                    standing: Standing::Mistake,
                    expect: swapped,
                },
                Variant {
                    name: "uv_without_pi",
                    says: "phi = atan2(-n.z, n.x) without + pi: u runs over [-0.5, 0.5]",
                    standing: Standing::Mistake,
                    expect: no_offset,
                },
                Variant {
                    name: "sphere_v_flipped",
                    says: "v = 1 - theta / pi (the course's v runs from -y to +y)",
                    standing: Standing::Mistake,
                    expect: flipped,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn quad_uv_check(seed: u64) -> FunctionCheck {
    let mut quads = vec![
        (
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            (0.25, 0.5),
        ),
        (
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(1.0, 2.0, -1.0),
            DVec3::new(1.0, 0.0, 1.0),
            (0.75, 0.125),
        ),
    ];
    let mut r = stream(seed, "quad-uv");
    for _ in 0..6 {
        let q = 2.0 * mistakes::unit_vector(&mut r);
        let u = mistakes::unit_vector(&mut r) * (0.5 + 2.0 * r.next_f64());
        let mut v = mistakes::unit_vector(&mut r) * (0.5 + 2.0 * r.next_f64());
        if u.cross(v).length() < 0.3 * u.length() * v.length() {
            v = u.cross(v).cross(u).normalize() * v.length();
        }
        quads.push((
            q,
            u,
            v,
            (0.05 + 0.9 * r.next_f64(), 0.05 + 0.9 * r.next_f64()),
        ));
    }
    let mut cases = Vec::new();
    let (mut unset, mut swapped) = (Vec::new(), Vec::new());
    for (k, &(q, u, v, (a, b))) in quads.iter().enumerate() {
        let quad = Quad::new(q, u, v);
        let p = q + a * u + b * v;
        let d = -(quad.normal + 0.3 * u.normalize());
        let origin = p - 3.0 * d;
        let ray = Ray::new(origin, d);
        let interval = [1e-6, f64::MAX];
        let hit = quad.intersect(&ray, Interval::new(interval[0], interval[1]));
        let Some(hit) = hit else { continue };
        let expect = |uv: (f64, f64)| {
            Expected::one("hit", Want::Bool(true)).and(
                "uv",
                Want::Pair {
                    value: [uv.0, uv.1],
                    tol: 1e-9,
                },
            )
        };
        cases.push(Case {
            id: format!("quad-uv-{k:04}"),
            request: json!({"op": "quad_uv", "quad": {"q": jvec(q), "u": jvec(u), "v": jvec(v)}, "ray": {"origin": jvec(origin), "direction": jvec(d)}, "interval": [jnum(interval[0]), jnum(interval[1])]}),
            expect: expect(hit.uv),
            class: Class::Definite,
            input: format!("Quad(Q = {}, u = {}, v = {}) hit from {} along {}", py::list(q), py::list(u), py::list(v), py::list(origin), py::list(d)),
            repro: py::script(
                &format!(
                    "h = rto.Quad({}, {}, {}).intersect({}, rtu.Interval(1e-06, rtu.infinity_number))\nprint(h.getUV())",
                    py::vec(q),
                    py::vec(u),
                    py::vec(v),
                    py::ray(origin, d, 0.0)
                ),
                &format!("({}, {})", py::f(hit.uv.0), py::f(hit.uv.1)),
            ),
        });
        unset.push(Some(expect((0.0, 0.0))));
        swapped.push(Some(expect((hit.uv.1, hit.uv.0))));
    }
    FunctionCheck {
        id: "quad-uv",
        function: "RT_object.Quad.intersect(ray, interval) (the hit's u, v)",
        week: week(7),
        given: false,
        op: "quad_uv",
        tolerance: "(u, v) = (alpha, beta) within 1e-9, on rays that hit well inside",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "quad_uv_not_set",
                    says: "Quad.intersect leaves (u, v) at (0, 0) instead of (alpha, beta)",
                    standing: Standing::Mistake,
                    expect: unset,
                },
                Variant {
                    name: "quad_uv_swapped",
                    says: "Quad.intersect sets (beta, alpha)",
                    standing: Standing::Mistake,
                    expect: swapped,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn color_want(c: DVec3, tol: f64) -> Expected {
    Expected::one("color", Want::vector(c, tol))
}

fn texture_case(
    id: String,
    texture: serde_json::Value,
    ctor: &str,
    uv: (f64, f64),
    p: DVec3,
    want: DVec3,
    class: Class,
) -> Case {
    Case {
        id,
        request: json!({"op": "texture", "texture": texture, "uv": [jnum(uv.0), jnum(uv.1)], "point": jvec(p)}),
        expect: color_want(want, 1e-12),
        class,
        input: format!(
            "{ctor}.tex_value({}, {}, {})",
            py::f(uv.0),
            py::f(uv.1),
            py::list(p)
        ),
        repro: py::script(
            &format!(
                "import RT_texture as rtt\nprint({ctor}.tex_value({}, {}, {}).e)",
                py::f(uv.0),
                py::f(uv.1),
                py::vec(p)
            ),
            &py::list(want),
        ),
    }
}

fn solid_check() -> FunctionCheck {
    let c = DVec3::new(0.8, 0.2, 0.5);
    let ctor = format!("rtt.SolidColor({})", py::color(c));
    let cases = [
        ((0.0, 0.0), DVec3::ZERO),
        ((0.3, 0.9), DVec3::new(1.0, -2.0, 3.0)),
    ]
    .iter()
    .enumerate()
    .map(|(k, &(uv, p))| {
        texture_case(
            format!("solid-{k:04}"),
            json!({"type": "solid", "color": jvec(c)}),
            &ctor,
            uv,
            p,
            c,
            Class::Definite,
        )
    })
    .collect();
    FunctionCheck {
        id: "solid-texture",
        function: "RT_texture.SolidColor.tex_value(u, v, p)",
        week: week(7),
        given: false,
        op: "texture",
        tolerance: "the colour within 1e-12",
        body: Body::Cases {
            cases,
            variants: Vec::new(),
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// Whether `x / s` is within a few ulps of an integer (a cell's edge).
fn near_edge(x: f64, s: f64) -> bool {
    let q = x / s;
    (q - q.round()).abs() <= 8.0 * f64::EPSILON * q.abs().max(1.0)
}

/// The checker's cases: `(scale, point)`, the course's scale first, then random ones.
fn checker_points(seed: u64) -> Vec<(f64, DVec3)> {
    let mut points: Vec<(f64, DVec3)> = [
        (0.1, 0.1, 0.1),
        (0.33, 0.1, 0.1),
        (-0.1, 0.1, 0.1),
        (0.33, 0.33, 0.1),
        (-0.1, -0.1, -0.1),
        (0.64, 0.0, 0.0),
        (0.6399, 0.0, 0.0),
        (1.7, -0.5, 2.2),
    ]
    .iter()
    .map(|&(x, y, z)| (0.32, DVec3::new(x, y, z)))
    .collect();
    let mut r = stream(seed, "checker");
    for k in 0..10 {
        let s = [0.32, 0.12, 1.0, 0.05][k % 4];
        points.push((s, 3.0 * mistakes::unit_vector(&mut r)));
    }
    points
}

fn checker_check(seed: u64) -> FunctionCheck {
    let (even, odd) = (DVec3::splat(0.2), DVec3::splat(0.9));
    let points = checker_points(seed);
    let uv = (0.5, 0.1);
    let mut cases = Vec::new();
    let mut variants: Vec<(&'static str, &'static str, Vec<Option<Expected>>)> = vec![
        (
            "checker_scale_wrong",
            "the checker multiplies the point by the scale instead of dividing",
            Vec::new(),
        ),
        (
            "checker_truncates_toward_zero",
            "the checker truncates with int() instead of floor(): the cells either side of each zero plane merge",
            Vec::new(),
        ),
        (
            "checker_on_uv",
            "the checker is computed on the texture coordinates (u, v) instead of the point",
            Vec::new(),
        ),
        (
            "checker_colours_swapped",
            "the checker gives the second colour where the sum of the cells is even",
            Vec::new(),
        ),
    ];
    for (k, &(s, p)) in points.iter().enumerate() {
        let tex = Texture::Checker {
            scale: s,
            even,
            odd,
        };
        let want = tex.value(&[], uv, p, Profile::Course);
        let edge = near_edge(p.x, s) || near_edge(p.y, s) || near_edge(p.z, s);
        let class = if edge {
            Class::Ambiguous(
                "a coordinate over the scale is within rounding of an integer (a cell's edge)"
                    .into(),
            )
        } else {
            Class::Definite
        };
        let pick = |cells: f64| {
            if cells.rem_euclid(2.0) == 0.0 {
                even
            } else {
                odd
            }
        };
        let scaled = pick((p.x * s).floor() + (p.y * s).floor() + (p.z * s).floor());
        let truncated = pick((p.x / s).trunc() + (p.y / s).trunc() + (p.z / s).trunc());
        let on_uv = pick((uv.0 / s).floor() + (uv.1 / s).floor());
        let swapped = if want == even { odd } else { even };
        let off_edge = |s2: f64| !(near_edge(p.x, s2) || near_edge(p.y, s2) || near_edge(p.z, s2));
        variants[0]
            .2
            .push(off_edge(1.0 / s).then(|| color_want(scaled, 1e-12)));
        variants[1]
            .2
            .push((!edge).then(|| color_want(truncated, 1e-12)));
        variants[2].2.push(Some(color_want(on_uv, 1e-12)));
        variants[3]
            .2
            .push((!edge).then(|| color_want(swapped, 1e-12)));
        let ctor = format!(
            "rtt.CheckerTexture({}, {}, {})",
            py::f(s),
            py::color(even),
            py::color(odd)
        );
        cases.push(texture_case(
            format!("checker-{k:04}"),
            json!({"type": "checker", "scale": jnum(s), "even": jvec(even), "odd": jvec(odd)}),
            &ctor,
            uv,
            p,
            want,
            class,
        ));
    }
    FunctionCheck {
        id: "checker-texture",
        function: "RT_texture.CheckerTexture.tex_value(u, v, p)",
        week: week(7),
        given: false,
        op: "texture",
        tolerance: "the colour within 1e-12; points within rounding of a cell's edge are not scored",
        body: Body::Cases {
            cases,
            variants: variants
                .into_iter()
                .map(|(name, says, expect)| Variant {
                    name,
                    says,
                    standing: Standing::Mistake,
                    expect,
                })
                .collect(),
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// A picture whose texels all differ: `(10 + 20 i + 60 j, ...)`, so a wrong texel shows.
fn picture(width: usize, height: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(3 * width * height);
    for j in 0..height {
        for i in 0..width {
            let base = 10 + 20 * i + 60 * j;
            rgb.extend([
                (base % 256) as u8,
                ((base + 10) % 256) as u8,
                ((base + 20) % 256) as u8,
            ]);
        }
    }
    rgb
}

/// Whether `u W` is within rounding of a texel edge (an integer other than 0).
fn near_texel_edge(u: f64, w: usize) -> bool {
    let x = u.clamp(0.0, 1.0) * w as f64;
    x != 0.0 && (x - x.round()).abs() <= 8.0 * f64::EPSILON * x.max(1.0)
}

fn image_check(seed: u64) -> FunctionCheck {
    let (w, h) = (4usize, 2usize);
    let rgb = picture(w, h);
    let image = TextureImage::new(w, h, &rgb, Profile::Course);
    let mut uvs = vec![
        (0.0, 0.0),
        (0.3, 0.6),
        (0.99, 0.49),
        (-1.0, 0.2),
        (0.5, 0.75),
        (1.0, 0.0),
        (0.5, 2.0),
        (0.625, 0.5),
    ];
    let mut r = stream(seed, "image");
    for _ in 0..8 {
        uvs.push((r.next_f64(), r.next_f64()));
    }
    let texture = json!({"type": "image", "width": w, "height": h, "rgb": rgb});
    let ctor = "rtt.ImageTexture('picture.png')";
    let bytes: Vec<u8> = rgb.clone();
    let mut cases = Vec::new();
    let (mut flipped, mut swapped, mut unscaled) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &(u, v)) in uvs.iter().enumerate() {
        let want = image.lookup((u, v));
        let (cu, cv) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let class = if cu == 1.0 || cv == 1.0 {
            Class::CourseFails("u or v is 1 after clamping: the course's int(u W) is one past the last texel (IndexError)".into())
        } else if near_texel_edge(u, w) || near_texel_edge(v, h) {
            Class::Ambiguous("u W or v H is within rounding of a texel's edge".into())
        } else {
            Class::Definite
        };
        let mut case = texture_case(
            format!("image-{k:04}"),
            texture.clone(),
            ctor,
            (u, v),
            DVec3::ZERO,
            want,
            class,
        );
        // The picture is written first: the {w} x {h} picture whose texel (i, j) is
        // (10 + 20 i + 60 j, +10, +20) mod 256, row 0 at the top.
        case.repro = case.repro.replacen(
            "import RT_texture as rtt\n",
            &format!("import RT_texture as rtt\nfrom PIL import Image\nImage.frombytes('RGB', ({w}, {h}), bytes({bytes:?})).save('picture.png')\n"),
            1,
        );
        cases.push(case);
        let ok = cu < 1.0 && cv < 1.0;
        flipped.push(
            (ok && cv > 0.0 && !near_texel_edge(1.0 - cv, h))
                .then(|| color_want(image.lookup((u, 1.0 - cv)), 1e-12)),
        );
        swapped.push(
            (ok && !near_texel_edge(v, w) && !near_texel_edge(u, h))
                .then(|| color_want(image.lookup((v, u)), 1e-12)),
        );
        unscaled.push(ok.then(|| color_want(want * 255.0, 1e-9)));
    }
    FunctionCheck {
        id: "image-texture",
        function: "RT_texture.ImageTexture.tex_value(u, v, p)",
        week: week(7),
        given: false,
        op: "texture",
        tolerance: "the texel (int(u W), int(v H)) / 255 within 1e-12; texel edges are not scored, nor u = 1 or v = 1 (the course's code raises IndexError)",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "v_flipped",
                    says: "ImageTexture reads row (1 - v) H, the book's flip, where the course reads v H",
                    standing: Standing::Mistake,
                    expect: flipped,
                },
                Variant {
                    name: "image_uv_swapped",
                    says: "ImageTexture reads column v W and row u H",
                    standing: Standing::Mistake,
                    expect: swapped,
                },
                Variant {
                    name: "image_not_divided_by_255",
                    says: "ImageTexture returns the bytes (0 to 255) without dividing by 255",
                    standing: Standing::Mistake,
                    expect: unscaled,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn textured_check(seed: u64) -> FunctionCheck {
    // A checker at hits on both sides of its cells; the direction is left to the Lambertian
    // checks (only the attenuation is judged: the texture's value at the hit point).
    let (even, odd) = (DVec3::new(0.2, 0.3, 0.1), DVec3::splat(0.9));
    let s = 0.32;
    let mut r = stream(seed, "textured");
    let mut cases = Vec::new();
    let mut uv_instead = Vec::new();
    for k in 0..6 {
        let n = mistakes::unit_vector(&mut r);
        let point = 2.0 * mistakes::unit_vector(&mut r);
        let h = HitInput {
            origin: point + 2.0 * n,
            direction: -2.0 * n,
            point,
            outward: n,
        };
        let tex = Texture::Checker {
            scale: s,
            even,
            odd,
        };
        let uv = (r.next_f64(), r.next_f64());
        let want = tex.value(&[], uv, point, Profile::Course);
        let edge = near_edge(point.x, s) || near_edge(point.y, s) || near_edge(point.z, s);
        let (ray, hit) = h.json();
        let mut hit = hit;
        hit["uv"] = json!([jnum(uv.0), jnum(uv.1)]);
        let expect = Expected::one("scattered", Want::Bool(true))
            .and("attenuation", Want::vector(want, 1e-12));
        cases.push(Case {
            id: format!("textured-{k:04}"),
            request: json!({"op": "scatter", "material": {"type": "textured", "texture": {"type": "checker", "scale": s, "even": jvec(even), "odd": jvec(odd)}}, "ray": ray, "hit": hit, "seed": k}),
            expect,
            class: if edge { Class::Ambiguous("the hit point is within rounding of a checker cell's edge".into()) } else { Class::Definite },
            input: format!("TextureColor(CheckerTexture({s}, ...)): {}, hit uv ({}, {})", h.words(), py::f(uv.0), py::f(uv.1)),
            repro: py::script(
                &format!(
                    "import RT_texture as rtt\n{}\nhit.set_uv({}, {})\nprint(m.scattering(ray, hit).attenuation_color.e)",
                    h.py(&format!("rtm.TextureColor(rtt.CheckerTexture({s}, {}, {}))", py::color(even), py::color(odd))),
                    py::f(uv.0),
                    py::f(uv.1)
                ),
                &py::list(want),
            ),
        });
        let pick = |cells: f64| {
            if cells.rem_euclid(2.0) == 0.0 {
                even
            } else {
                odd
            }
        };
        uv_instead.push((!edge).then(|| {
            Expected::one("scattered", Want::Bool(true)).and(
                "attenuation",
                Want::vector(pick((uv.0 / s).floor() + (uv.1 / s).floor()), 1e-12),
            )
        }));
    }
    FunctionCheck {
        id: "textured",
        function: "RT_material.TextureColor.scattering(ray, hit) (its attenuation)",
        week: week(7),
        given: false,
        op: "scatter",
        tolerance: "the attenuation (the texture's value at the hit) within 1e-12",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "checker_on_uv",
                says: "the texture is read at the hit's (u, v) where the course's checker reads the point",
                standing: Standing::Mistake,
                expect: uv_instead,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}
