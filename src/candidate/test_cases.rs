//! Five hand-checked cases with closed-form answers (a ray down the z axis onto a unit sphere,
//! a 2x2 quad and a triangle at known distances), for unit tests that need fixed vectors.

use crate::oracle::vectors::{Case, Class, Expect, RaySpec, ShapeSpec};

/// The default suite for `seed`: every case `rtoracle check` runs when no vector file is given.
/// The five cases.
pub(crate) fn basic_cases() -> Vec<Case> {
    let expect = |class, t: Option<f64>, normal: Option<[f64; 3]>| Expect {
        class,
        tags: vec![],
        t,
        t_tol: t.map(|t| 1e-9 * t),
        point: None,
        normal,
        front_face: t.map(|_| true),
        normal_tol: None,
        watertight: None,
    };
    let down = RaySpec {
        origin: [0.0, 0.0, 5.0],
        direction: [0.0, 0.0, -1.0],
    };
    vec![
        Case {
            id: "sphere-basic-0000".into(),
            shape: ShapeSpec::Sphere {
                center: [0.0, 0.0, 0.0],
                radius: 1.0,
            },
            ray: down,
            interval: [1e-6, f64::MAX],
            expect: expect(Class::Hit, Some(4.0), Some([0.0, 0.0, 1.0])),
        },
        Case {
            id: "sphere-basic-0001".into(),
            shape: ShapeSpec::Sphere {
                center: [3.0, 0.0, 0.0],
                radius: 1.0,
            },
            ray: down,
            interval: [1e-6, f64::MAX],
            expect: expect(Class::Miss, None, None),
        },
        Case {
            id: "quad-basic-0000".into(),
            shape: ShapeSpec::Quad {
                q: [-1.0, -1.0, 0.0],
                u: [2.0, 0.0, 0.0],
                v: [0.0, 2.0, 0.0],
            },
            ray: down,
            interval: [1e-6, f64::MAX],
            expect: expect(Class::Hit, Some(5.0), Some([0.0, 0.0, 1.0])),
        },
        Case {
            id: "quad-basic-0001".into(),
            shape: ShapeSpec::Quad {
                q: [2.0, -1.0, 0.0],
                u: [2.0, 0.0, 0.0],
                v: [0.0, 2.0, 0.0],
            },
            ray: down,
            interval: [1e-6, f64::MAX],
            expect: expect(Class::Miss, None, None),
        },
        Case {
            id: "triangle-basic-0000".into(),
            shape: ShapeSpec::Triangle {
                a: [-1.0, -1.0, 0.0],
                b: [1.0, -1.0, 0.0],
                c: [0.0, 1.0, 0.0],
            },
            ray: down,
            interval: [1e-6, f64::MAX],
            expect: expect(Class::Hit, Some(5.0), Some([0.0, 0.0, 1.0])),
        },
    ]
}
