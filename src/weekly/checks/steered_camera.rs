//! The camera's jittered ray with its random numbers steered (`camera-ray`): week 9's jitter
//! (the camera's own numpy generator, `camera_rng.uniform`) and week 10's jitter, lens and time
//! (the course's `random_double`, its `Vec3.random_vec3_in_unit_disk()` included), each exact for
//! course-shaped code ([`super::steer`]).
//!
//! The course's `get_jittered_ray(i, j, s_i, s_j)` takes `pixel00 + du i + dv j`, adds
//! `(du px + dv py) 0.5` with `px = -0.5 + step (s_i + U)` and `py = -0.5 + step (s_j + U)`
//! (`step` its frozen `one_over_sqrt_spp`: 1/3 in week 9, `1/sqrt(10)` in week 10), then in week
//! 10 starts the ray at `center + disk_u x + disk_v y` for a point of the unit disk (drawn as
//! `random_double(-1, 1)` pairs until `x x + y y < 1`) when the defocus angle is above `1e-6`,
//! and gives it the time `random_double()`. An answer drawn otherwise counts when it keeps the
//! invariants of the statistical checks of the same ray (`jitter`, and in week 10 `lens` and
//! `ray-time`) and they passed.

use glam::DVec3;
use serde_json::json;

use super::camera::{CameraInput, dof_camera};
use super::steer::{self, Behaviour};
use super::{Body, CASE_TIMEOUT, Case, FunctionCheck, jnum, py, stream, week};
use crate::weekly::expect::{Class, Expected, Want, numbers};
use crate::weekly::samplers::{Sample, SamplerCheck, camera::JitterSetting};

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![camera_ray_check(seed, 9), camera_ray_check(seed, 10)]
}

/// A camera-ray answer (one sample: origin, direction, time) as the keys it is judged on.
fn as_ray(answer: serde_json::Value) -> serde_json::Value {
    let Some(s) = answer
        .get("samples")
        .and_then(serde_json::Value::as_array)
        .and_then(|s| s.first())
        .and_then(|s| numbers(Some(s), 7))
    else {
        return answer;
    };
    json!({"origin": [s[0], s[1], s[2]], "direction": [s[3], s[4], s[5]], "time": s[6]})
}

/// The setting of one week's camera-ray cases.
struct Setting {
    camera: CameraInput,
    step: f64,
    strata: u32,
    lens: bool,
}

impl Setting {
    fn of(of: u8) -> Setting {
        if of == 9 {
            Setting {
                camera: dof_camera(30, 0.0),
                step: 1.0 / 3.0,
                strata: 5,
                lens: false,
            }
        } else {
            Setting {
                camera: dof_camera(100, 2.0),
                step: 1.0 / 10f64.sqrt(),
                strata: 10,
                lens: true,
            }
        }
    }

    /// What the course's ray is for pixel `(i, j)`, stratum `s` and the values: the jitter's
    /// two, then (week 10) the disk's pairs and the time's one. `None` if they run out.
    fn course_ray(
        &self,
        (i, j): (usize, usize),
        s: (u32, u32),
        values: &[f64],
    ) -> Option<[DVec3; 2]> {
        let cam = self.camera.reference();
        let (du, dv) = (cam.pixel_delta_u, cam.pixel_delta_v);
        let px = -0.5 + self.step * (s.0 as f64 + values[0]);
        let py = -0.5 + self.step * (s.1 as f64 + values[1]);
        let centre = cam.pixel00 + du * i as f64 + dv * j as f64;
        let sample = centre + (du * px + dv * py) * 0.5;
        let mut origin = cam.center;
        if self.lens {
            let disk = values[2..values.len() - 1].chunks_exact(2).find_map(|p| {
                let (x, y) = (
                    steer::scaled(p[0], -1.0, 1.0),
                    steer::scaled(p[1], -1.0, 1.0),
                );
                (x * x + y * y + 0.0 * 0.0 < 1.0).then_some((x, y))
            })?;
            origin = cam.center + cam.defocus_disk_u * disk.0 + cam.defocus_disk_v * disk.1;
        }
        Some([origin, sample - origin])
    }

    /// What any answer must keep: the ray through its stratum of the pixel, from the lens and
    /// with a time in `[0, 1)` (the statistical checks' invariants).
    fn behaviour(&self, pixel: (usize, usize), stratum: (u32, u32)) -> Behaviour {
        let cam = self.camera.reference();
        let (u, v, w, radius) = self.camera.frame();
        let (du, dv) = (cam.pixel_delta_u, cam.pixel_delta_v);
        let centre = cam.pixel00 + du * pixel.0 as f64 + dv * pixel.1 as f64;
        let jitter = SamplerCheck::jitter(JitterSetting {
            stratum,
            step: self.step,
            unfrozen_step: self.step,
        });
        let lens = self.lens.then(|| SamplerCheck::lens(2.0));
        let time = self.lens.then(SamplerCheck::ray_time);
        let eye = cam.center;
        Box::new(move |answer| {
            let get = |k: &str, n: usize| {
                numbers(answer.get(k), n).ok_or_else(|| format!("its {k} is not {n} numbers"))
            };
            let (o, d) = (get("origin", 3)?, get("direction", 3)?);
            let (o, d) = (DVec3::from_slice(&o), DVec3::from_slice(&d));
            let off = o + d - centre;
            let pad = |xs: &[f64]| -> Sample {
                let mut s = [0.0; 9];
                s[..xs.len()].copy_from_slice(xs);
                s
            };
            jitter.course.invariant_holds(&pad(&[
                off.dot(du) / du.length_squared(),
                off.dot(dv) / dv.length_squared(),
            ]))?;
            if let (Some(lens), Some(time)) = (&lens, &time) {
                let e = o - eye;
                lens.course.invariant_holds(&pad(&[
                    e.dot(u) / radius,
                    e.dot(v) / radius,
                    e.dot(w),
                ]))?;
                let t = answer
                    .get("time")
                    .and_then(|t| numbers(Some(&json!([t])), 1))
                    .ok_or("its time is not a number")?;
                time.course.invariant_holds(&pad(&t))?;
            }
            Ok(())
        })
    }
}

/// The values of one case: the jitter's two, then (week 10) a disk point, after one the loop
/// throws away for odd `k`, and the time.
fn case_values(r: &mut crate::render::PixelSampler, k: usize, lens: bool) -> Vec<f64> {
    let mut values = vec![r.next_f64(), r.next_f64()];
    if lens {
        // Inside: well within the disk; outside: a point the course's loop throws away.
        let pair = |r: &mut crate::render::PixelSampler, inside: bool| loop {
            let p = [r.next_f64(), r.next_f64()];
            let (x, y) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
            let l = x * x + y * y;
            if (inside && l < 0.99) || (!inside && l >= 1.0) {
                break p;
            }
        };
        if k % 2 == 1 {
            values.extend(pair(r, false));
        }
        values.extend(pair(r, true));
        values.push(r.next_f64());
    }
    values
}

fn camera_ray_check(seed: u64, of: u8) -> FunctionCheck {
    let setting = Setting::of(of);
    let cam = setting.camera.reference();
    let mut r = stream(seed, &format!("camera-ray-{of}"));
    let mut cases = Vec::new();
    let mut behaviour = Vec::new();
    for k in 0..8 {
        let pixel = if k == 0 {
            (3, 4)
        } else {
            (
                (r.next_f64() * cam.width as f64) as usize,
                (r.next_f64() * cam.height as f64) as usize,
            )
        };
        let n = setting.strata;
        let stratum = (
            (r.next_f64() * n as f64) as u32,
            (r.next_f64() * n as f64) as u32,
        );
        let values = case_values(&mut r, k, setting.lens);
        let [origin, direction] = setting
            .course_ray(pixel, stratum, &values)
            .expect("values for one ray");
        let time = if setting.lens {
            values[values.len() - 1]
        } else {
            0.0
        };
        let id = format!("camera-ray-{k:04}");
        let replace = if setting.lens {
            json!({"random_double": values.iter().map(|&v| jnum(v)).collect::<Vec<_>>()})
        } else {
            json!({"rng": values.iter().map(|&v| jnum(v)).collect::<Vec<_>>()})
        };
        let tol = 1e-9 * direction.length().max(1.0);
        cases.push(Case {
            request: json!({"op": "sample_camera_ray", "camera": setting.camera.json(), "pixel": [pixel.0, pixel.1], "stratum": [stratum.0, stratum.1], "n": 1, "seed": steer::case_seed(seed, &id), "replace": replace}),
            id,
            expect: Expected::one("origin", Want::vector(origin, tol))
                .and("direction", Want::vector(direction, tol))
                .and("time", Want::Number { value: time, tol: 1e-12 }),
            class: Class::Definite,
            input: format!(
                "get_jittered_ray({}, {}, {}, {}) with {} = {}",
                pixel.0,
                pixel.1,
                stratum.0,
                stratum.1,
                if setting.lens { "random_double()" } else { "camera_rng.uniform()" },
                values.iter().map(|&v| py::f(v)).collect::<Vec<_>>().join(", ")
            ),
            repro: py::script(
                &format!(
                    "{}\n{}\nr = cam.get_jittered_ray({}, {}, {}, {})\nprint({{'origin': r.getOrigin().e, 'direction': r.getDirection().e{}}})",
                    setting.camera.py(),
                    if setting.lens {
                        py::random_doubles(&values)
                    } else {
                        format!(
                            "class SteeredRng:\n    def __init__(self, values):\n        self.values = iter(values)\n    def uniform(self, low=0.0, high=1.0):\n        return low + next(self.values) * (high - low)\ncam.camera_rng = SteeredRng([{}])",
                            values.iter().map(|&v| py::f(v)).collect::<Vec<_>>().join(", ")
                        )
                    },
                    pixel.0,
                    pixel.1,
                    stratum.0,
                    stratum.1,
                    if setting.lens { ", 'time': r.getTime()" } else { "" }
                ),
                &format!("origin {}, direction {}", py::list(origin), py::list(direction)),
            ),
        });
        behaviour.push(setting.behaviour(pixel, stratum));
    }
    FunctionCheck {
        id: "camera-ray",
        function: "RT_camera.Camera.get_jittered_ray(i, j, s_i, s_j) (steered)",
        week: week(of),
        given: false,
        op: "sample_camera_ray",
        tolerance: if of == 9 {
            "with camera_rng.uniform() steered: the ray through pixel00 + du i + dv j + (du px + dv py) / 2, px = -0.5 + step (s_i + U), within 1e-9 max(1, |d|); an answer drawn otherwise counts when it lies in its stratum and jitter passes"
        } else {
            "with random_double() steered: the jittered ray from the lens point center + disk_u x + disk_v y, with the time U, within 1e-9 max(1, |d|); an answer drawn otherwise counts when it keeps the jitter, lens and time invariants and jitter, lens and ray-time pass"
        },
        body: Body::Steered {
            cases,
            variants: Vec::new(),
            partners: if of == 9 {
                &["jitter"]
            } else {
                &["jitter", "lens", "ray-time"]
            },
            behaviour,
            normalise: Some(as_ray),
        },
        timeout: CASE_TIMEOUT,
    }
}
