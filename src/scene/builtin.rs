//! The built-in scenes: the course's two week-4 scenes, exactly as its main program builds them,
//! and two of rtoracle's own that exercise triangles and edge cases.

use super::file::MaterialKind;
use super::{
    CameraSettings, ImageSettings, MaterialEntry, ObjectEntry, SceneDescription, SceneError,
};

/// A scene that ships inside the binary.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinScene {
    /// The name `render` and `compare --scene` take.
    pub name: &'static str,
    /// One line saying what it shows.
    pub summary: &'static str,
    build: fn() -> SceneDescription,
}

impl BuiltinScene {
    /// The scene's description.
    pub fn description(&self) -> SceneDescription {
        (self.build)()
    }
}

/// Every built-in scene, in the order `rtoracle scenes` lists them.
pub const BUILTIN_SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "week04-sphere",
        summary: "the course's week-4 sphere scene: ground, three spheres and a hollow one, 400x225",
        build: week04_sphere,
    },
    BuiltinScene {
        name: "week04-quad",
        summary: "the course's week-4 quad scene: five coloured quads seen from z = 10, 400x400",
        build: week04_quad,
    },
    BuiltinScene {
        name: "triangles",
        summary: "triangles, a quad split into two triangles along its diagonal, and a fan, 400x300",
        build: triangles,
    },
    BuiltinScene {
        name: "edge-cases",
        summary: "grazing and tangent views, a tiny and a huge sphere, a hollow sphere, a skinny quad, 400x300",
        build: edge_cases,
    },
];

/// The built-in scene called `name`.
pub fn builtin(name: &str) -> Result<SceneDescription, SceneError> {
    BUILTIN_SCENES
        .iter()
        .find(|s| s.name == name)
        .map(BuiltinScene::description)
        .ok_or_else(|| SceneError::Unknown {
            name: name.to_string(),
        })
}

/// The names of the built-in scenes.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN_SCENES.iter().map(|s| s.name).collect()
}

fn lambertian(name: &str, albedo: [f64; 3]) -> MaterialEntry {
    MaterialEntry {
        name: name.to_string(),
        kind: MaterialKind::Lambertian,
        albedo,
    }
}

fn sphere(center: [f64; 3], radius: f64, material: &str) -> ObjectEntry {
    ObjectEntry::Sphere {
        center,
        radius,
        material: material.to_string(),
    }
}

fn quad(q: [f64; 3], u: [f64; 3], v: [f64; 3], material: &str) -> ObjectEntry {
    ObjectEntry::Quad {
        q,
        u,
        v,
        material: material.to_string(),
    }
}

fn triangle(a: [f64; 3], b: [f64; 3], c: [f64; 3], material: &str) -> ObjectEntry {
    ObjectEntry::Triangle {
        a,
        b,
        c,
        material: material.to_string(),
    }
}

fn course_camera(look_from: [f64; 3], look_at: [f64; 3]) -> CameraSettings {
    CameraSettings {
        look_from,
        look_at,
        up: [0.0, 1.0, 0.0],
        vfov: 90.0,
        focus_distance: 10.0,
        defocus_angle: 0.0,
    }
}

fn week04_sphere() -> SceneDescription {
    SceneDescription {
        image: ImageSettings {
            width: 400,
            aspect_ratio: 16.0 / 9.0,
            samples_per_pixel: 20,
        },
        camera: course_camera([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
        materials: vec![
            lambertian("ground", [0.0, 0.0, 0.8]),
            lambertian("center", [0.8, 0.8, 0.0]),
            lambertian("left", [0.8, 0.0, 0.0]),
            lambertian("bubble", [0.8, 0.8, 0.0]),
            lambertian("right", [0.8, 0.0, 0.0]),
        ],
        objects: vec![
            sphere([0.0, -100.5, -1.0], 100.0, "ground"),
            sphere([0.0, 0.0, -1.0], 0.5, "center"),
            sphere([-1.0, 0.0, -1.0], 0.5, "left"),
            sphere([-1.0, 0.0, -1.0], -0.4, "bubble"),
            sphere([1.0, 0.0, -1.0], 0.5, "right"),
        ],
    }
}

fn week04_quad() -> SceneDescription {
    SceneDescription {
        image: ImageSettings {
            width: 400,
            aspect_ratio: 1.0,
            samples_per_pixel: 20,
        },
        camera: course_camera([0.0, 0.0, 10.0], [0.0, 0.0, 0.0]),
        materials: vec![
            lambertian("left_red", [1.0, 0.2, 0.2]),
            lambertian("back_green", [0.2, 1.0, 0.2]),
            lambertian("right_blue", [0.2, 0.2, 1.0]),
            lambertian("upper_orange", [1.0, 0.5, 0.0]),
            lambertian("lower_teal", [0.2, 0.8, 0.8]),
        ],
        objects: vec![
            quad(
                [-3.0, -2.0, 5.0],
                [0.0, 0.0, -4.0],
                [0.0, 4.0, 0.0],
                "left_red",
            ),
            quad(
                [-2.0, -2.0, 0.0],
                [4.0, 0.0, 0.0],
                [0.0, 4.0, 0.0],
                "back_green",
            ),
            quad(
                [3.0, -2.0, 1.0],
                [0.0, 0.0, 4.0],
                [0.0, 4.0, 0.0],
                "right_blue",
            ),
            quad(
                [-2.0, 3.0, 1.0],
                [4.0, 0.0, 0.0],
                [0.0, 0.0, 4.0],
                "upper_orange",
            ),
            quad(
                [-2.0, -3.0, 5.0],
                [4.0, 0.0, 0.0],
                [0.0, 0.0, -4.0],
                "lower_teal",
            ),
        ],
    }
}

fn triangles() -> SceneDescription {
    SceneDescription {
        image: ImageSettings {
            width: 400,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: 20,
        },
        camera: course_camera([0.0, 0.0, 6.0], [0.0, 0.0, 0.0]),
        materials: vec![
            lambertian("floor", [0.5, 0.5, 0.5]),
            lambertian("lower", [0.9, 0.3, 0.1]),
            lambertian("upper", [0.1, 0.3, 0.9]),
            lambertian("fan_a", [0.2, 0.8, 0.2]),
            lambertian("fan_b", [0.8, 0.8, 0.2]),
            lambertian("tilted", [0.7, 0.2, 0.7]),
        ],
        objects: vec![
            // A floor quad under everything.
            quad(
                [-8.0, -2.5, 4.0],
                [16.0, 0.0, 0.0],
                [0.0, 0.0, -12.0],
                "floor",
            ),
            // A square split along its diagonal (-3,-1,0)-(-1,1,0): no pixel may fall through.
            triangle(
                [-3.0, -1.0, 0.0],
                [-1.0, -1.0, 0.0],
                [-1.0, 1.0, 0.0],
                "lower",
            ),
            triangle(
                [-3.0, -1.0, 0.0],
                [-1.0, 1.0, 0.0],
                [-3.0, 1.0, 0.0],
                "upper",
            ),
            // A fan of four triangles around (1.5, 0, 0), alternating colours.
            triangle([1.5, 0.0, 0.0], [2.75, 0.0, 0.0], [1.5, 1.25, 0.0], "fan_a"),
            triangle([1.5, 0.0, 0.0], [1.5, 1.25, 0.0], [0.25, 0.0, 0.0], "fan_b"),
            triangle(
                [1.5, 0.0, 0.0],
                [0.25, 0.0, 0.0],
                [1.5, -1.25, 0.0],
                "fan_a",
            ),
            triangle(
                [1.5, 0.0, 0.0],
                [1.5, -1.25, 0.0],
                [2.75, 0.0, 0.0],
                "fan_b",
            ),
            // A tilted triangle seen partly from behind.
            triangle(
                [-0.75, 1.5, -1.0],
                [0.75, 1.5, 1.0],
                [0.0, 2.6, -0.5],
                "tilted",
            ),
        ],
    }
}

fn edge_cases() -> SceneDescription {
    SceneDescription {
        image: ImageSettings {
            width: 400,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: 20,
        },
        camera: course_camera([0.0, 0.0, 4.0], [0.0, 0.0, 0.0]),
        materials: vec![
            lambertian("huge", [0.3, 0.3, 0.35]),
            lambertian("tangent", [0.9, 0.9, 0.2]),
            lambertian("tiny", [1.0, 0.1, 0.1]),
            lambertian("shell", [0.2, 0.7, 0.9]),
            lambertian("hollow", [0.9, 0.5, 0.1]),
            lambertian("grazing", [0.3, 0.9, 0.3]),
            lambertian("skinny", [0.9, 0.2, 0.9]),
        ],
        objects: vec![
            // A huge sphere whose top is the horizon seen almost edge-on.
            sphere([0.0, -1.0e6 - 1.5, 0.0], 1.0e6, "huge"),
            // A sphere whose silhouette rays are tangent to it along the image's middle row.
            sphere([-2.0, 0.0, 0.0], 1.0, "tangent"),
            // A sphere smaller than a pixel.
            sphere([0.6, 1.2, 0.0], 0.004, "tiny"),
            // A hollow sphere: a shell with a negative-radius inner surface.
            sphere([1.8, 0.3, -0.5], 0.8, "shell"),
            sphere([1.8, 0.3, -0.5], -0.7, "hollow"),
            // A quad seen at a grazing angle: its plane almost contains the eye.
            quad(
                [-1.0, -1.4, 3.0],
                [2.0, 0.0, 0.0],
                [0.0, 0.02, -4.0],
                "grazing",
            ),
            // A skinny, skewed quad.
            quad(
                [-0.5, 1.0, -1.0],
                [1.5, 0.6, 0.0],
                [0.01, 0.02, 0.0],
                "skinny",
            ),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_is_valid_and_round_trips_through_toml() {
        for s in BUILTIN_SCENES {
            let d = s.description();
            d.validate(s.name).unwrap();
            let back = SceneDescription::from_toml(&d.to_toml(), s.name).unwrap();
            assert_eq!(back, d, "{}", s.name);
        }
    }

    /// `up`, `focus_distance` and `defocus_angle` may be left out of a scene file: the scene is
    /// then the one with the book's values (`vup = (0, 1, 0)`, `focus_dist = 10`,
    /// `defocus_angle = 0`), which every built-in states explicitly.
    #[test]
    fn a_scene_file_may_leave_out_the_book_s_camera_defaults() {
        for s in BUILTIN_SCENES {
            let d = s.description();
            assert_eq!(
                (d.camera.up, d.camera.focus_distance, d.camera.defocus_angle),
                ([0.0, 1.0, 0.0], 10.0, 0.0),
                "{}",
                s.name
            );
            let text = d.to_toml();
            let short: String = text
                .lines()
                .filter(|l| {
                    !["up ", "up=", "focus_distance", "defocus_angle"]
                        .iter()
                        .any(|k| l.trim_start().starts_with(k))
                })
                .map(|l| format!("{l}\n"))
                .collect();
            assert_eq!(
                text.lines().count() - short.lines().count(),
                3,
                "{}: the three lines are left out",
                s.name
            );
            let back = SceneDescription::from_toml(&short, s.name).unwrap();
            assert_eq!(back, d, "{}", s.name);
        }
    }
}
