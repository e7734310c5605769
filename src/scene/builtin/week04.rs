//! The course's two week-4 scenes, exactly as its main program builds them, and two of
//! rtoracle's own that exercise triangles and edge cases (albedo of the closest hit, the sky).

use super::parts::{course_camera, lambertian, quad, sphere, triangle};
use crate::scene::{ImageSettings, SceneDescription};

pub(super) fn week04_sphere() -> SceneDescription {
    SceneDescription::new(
        ImageSettings {
            width: 400,
            aspect_ratio: 16.0 / 9.0,
            samples_per_pixel: 20,
        },
        course_camera([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
        vec![
            lambertian("ground", [0.0, 0.0, 0.8]),
            lambertian("center", [0.8, 0.8, 0.0]),
            lambertian("left", [0.8, 0.0, 0.0]),
            lambertian("bubble", [0.8, 0.8, 0.0]),
            lambertian("right", [0.8, 0.0, 0.0]),
        ],
        vec![
            sphere([0.0, -100.5, -1.0], 100.0, "ground"),
            sphere([0.0, 0.0, -1.0], 0.5, "center"),
            sphere([-1.0, 0.0, -1.0], 0.5, "left"),
            sphere([-1.0, 0.0, -1.0], -0.4, "bubble"),
            sphere([1.0, 0.0, -1.0], 0.5, "right"),
        ],
    )
}

pub(super) fn week04_quad() -> SceneDescription {
    SceneDescription::new(
        ImageSettings {
            width: 400,
            aspect_ratio: 1.0,
            samples_per_pixel: 20,
        },
        course_camera([0.0, 0.0, 10.0], [0.0, 0.0, 0.0]),
        vec![
            lambertian("left_red", [1.0, 0.2, 0.2]),
            lambertian("back_green", [0.2, 1.0, 0.2]),
            lambertian("right_blue", [0.2, 0.2, 1.0]),
            lambertian("upper_orange", [1.0, 0.5, 0.0]),
            lambertian("lower_teal", [0.2, 0.8, 0.8]),
        ],
        vec![
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
    )
}

pub(super) fn triangles() -> SceneDescription {
    SceneDescription::new(
        ImageSettings {
            width: 400,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: 20,
        },
        course_camera([0.0, 0.0, 6.0], [0.0, 0.0, 0.0]),
        vec![
            lambertian("floor", [0.5, 0.5, 0.5]),
            lambertian("lower", [0.9, 0.3, 0.1]),
            lambertian("upper", [0.1, 0.3, 0.9]),
            lambertian("fan_a", [0.2, 0.8, 0.2]),
            lambertian("fan_b", [0.8, 0.8, 0.2]),
            lambertian("tilted", [0.7, 0.2, 0.7]),
        ],
        vec![
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
    )
}

pub(super) fn edge_cases() -> SceneDescription {
    SceneDescription::new(
        ImageSettings {
            width: 400,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: 20,
        },
        course_camera([0.0, 0.0, 4.0], [0.0, 0.0, 0.0]),
        vec![
            lambertian("huge", [0.3, 0.3, 0.35]),
            lambertian("tangent", [0.9, 0.9, 0.2]),
            lambertian("tiny", [1.0, 0.1, 0.1]),
            lambertian("shell", [0.2, 0.7, 0.9]),
            lambertian("hollow", [0.9, 0.5, 0.1]),
            lambertian("grazing", [0.3, 0.9, 0.3]),
            lambertian("skinny", [0.9, 0.2, 0.9]),
        ],
        vec![
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
    )
}
