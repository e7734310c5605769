//! The built-in scenes: the course's scenes of weeks 4 to 10, as its main programs build them,
//! two of rtoracle's own that exercise triangles and edge cases, and *Ray Tracing in One
//! Weekend*'s material scenes.

mod parts;
mod rtiow;
mod week04;
mod weeks;

pub use parts::TextureSource;
pub use rtiow::rtiow_final_scene;

use crate::scene::{Profile, SceneDescription, SceneError};

/// How a built-in scene is made.
#[derive(Clone, Copy, Debug)]
enum Build {
    /// From nothing.
    Fixed(fn() -> SceneDescription),
    /// With its image textures from a source.
    Textured(fn(&TextureSource) -> Result<SceneDescription, SceneError>),
}

/// A scene that ships inside the binary.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinScene {
    /// The name `render` and `compare --scene` take.
    pub name: &'static str,
    /// One line saying what it shows.
    pub summary: &'static str,
    /// The course's week it comes from (`None` for rtoracle's own scenes and the book's).
    pub week: Option<u32>,
    /// The profiles it is meant to be rendered in, its own (the description's) first.
    pub profiles: &'static [Profile],
    build: Build,
}

impl BuiltinScene {
    /// The scene's description, with generated pictures for its image textures.
    pub fn description(&self) -> SceneDescription {
        match self.build {
            Build::Fixed(build) => build(),
            Build::Textured(build) => {
                build(&TextureSource::Generated).expect("generated pictures are always found")
            }
        }
    }

    /// The scene's description with its image textures from `source`.
    pub fn description_with(&self, source: &TextureSource) -> Result<SceneDescription, SceneError> {
        match self.build {
            Build::Fixed(build) => Ok(build()),
            Build::Textured(build) => build(source),
        }
    }

    /// Whether the scene has image textures (which `--textures` can replace by the course's).
    pub fn has_pictures(&self) -> bool {
        matches!(self.build, Build::Textured(_))
    }
}

const COURSE: &[Profile] = &[Profile::Course];
const BOTH: &[Profile] = &[Profile::Course, Profile::Physical];
const PHYSICAL: &[Profile] = &[Profile::Physical];

/// Every built-in scene, in the order `rtoracle scenes` lists them.
pub const BUILTIN_SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "week04-sphere",
        summary: "the course's week-4 sphere scene: ground, three spheres and a hollow one, 400x225",
        week: Some(4),
        profiles: COURSE,
        build: Build::Fixed(week04::week04_sphere),
    },
    BuiltinScene {
        name: "week04-quad",
        summary: "the course's week-4 quad scene: five coloured quads seen from z = 10, 400x400",
        week: Some(4),
        profiles: COURSE,
        build: Build::Fixed(week04::week04_quad),
    },
    BuiltinScene {
        name: "triangles",
        summary: "triangles, a quad split into two triangles along its diagonal, and a fan, 400x300",
        week: None,
        profiles: COURSE,
        build: Build::Fixed(week04::triangles),
    },
    BuiltinScene {
        name: "edge-cases",
        summary: "grazing and tangent views, a tiny and a huge sphere, a hollow sphere, a skinny quad, 400x300",
        week: None,
        profiles: COURSE,
        build: Build::Fixed(week04::edge_cases),
    },
    BuiltinScene {
        name: "week05-quad",
        summary: "renderQuad: the week-4 quads lit by the 0.01 background alone, depth 3, 400x400, 20 spp",
        week: Some(5),
        profiles: BOTH,
        build: Build::Fixed(weeks::week05_quad),
    },
    BuiltinScene {
        name: "week05-quad-light",
        summary: "renderQuadLight: the right quad is a light, depth 8, 400x400, 10 spp",
        week: Some(5),
        profiles: BOTH,
        build: Build::Fixed(weeks::week05_quad_light),
    },
    BuiltinScene {
        name: "week05-point-light",
        summary: "renderPointLight: the quads and a point light at the origin, depth 4, 400x400, 10 spp",
        week: Some(5),
        profiles: COURSE,
        build: Build::Fixed(weeks::week05_point_light),
    },
    BuiltinScene {
        name: "week05-point-light-shadow",
        summary: "renderPointLightShadow: the point light at (4, 0, 0), behind the right quad, 400x400, 10 spp",
        week: Some(5),
        profiles: COURSE,
        build: Build::Fixed(weeks::week05_point_light_shadow),
    },
    BuiltinScene {
        name: "week06-mirror-point-light",
        summary: "renderMirrorPointLight: mirror spheres and a point light, vfov 30, depth 7, 400x225, 20 spp",
        week: Some(6),
        profiles: COURSE,
        build: Build::Fixed(weeks::week06_mirror_point_light),
    },
    BuiltinScene {
        name: "week06-mirrors",
        summary: "renderMirrors: mirror spheres under the sky, depth 7, 400x225, 20 spp",
        week: Some(6),
        profiles: BOTH,
        build: Build::Fixed(weeks::week06_mirrors),
    },
    BuiltinScene {
        name: "week06-dielectric",
        summary: "renderDielectric: a glass sphere (IOR 1.5) beside the mirrors, depth 7, 400x225, 20 spp",
        week: Some(6),
        profiles: BOTH,
        build: Build::Fixed(weeks::week06_dielectric),
    },
    BuiltinScene {
        name: "week07-procedural-texture",
        summary: "renderProceduralTexture: two checkers, a solid colour and a Lambertian sphere, depth 5, 400x225, 20 spp",
        week: Some(7),
        profiles: BOTH,
        build: Build::Fixed(weeks::week07_procedural_texture),
    },
    BuiltinScene {
        name: "week07-earth",
        summary: "renderEarth: the earth picture on the ground, pictures on two spheres and a quad, depth 5, 400x225, 20 spp",
        week: Some(7),
        profiles: BOTH,
        build: Build::Textured(weeks::week07_earth),
    },
    BuiltinScene {
        name: "week08-phong",
        summary: "renderPhong: Phong spheres (alpha 0.8, 8, 30) and a point light, depth 5, 320x180, 30 spp",
        week: Some(8),
        profiles: COURSE,
        build: Build::Fixed(weeks::week08_phong),
    },
    BuiltinScene {
        name: "week08-blinn",
        summary: "renderBlinn: Blinn spheres (alpha 0.08, 8, 300) and a point light, depth 5, 320x180, 30 spp",
        week: Some(8),
        profiles: COURSE,
        build: Build::Fixed(weeks::week08_blinn),
    },
    BuiltinScene {
        name: "week09-blinn",
        summary: "renderBlinn: Blinn spheres under the sky, cosine-sampled bounces, render(), depth 5, 320x180, 30 spp",
        week: Some(9),
        profiles: COURSE,
        build: Build::Fixed(weeks::week09_blinn),
    },
    BuiltinScene {
        name: "week10-dof",
        summary: "renderDoF: week 9's spheres at alpha 8 with a 2-degree defocus, jittered, 320x180, 100 spp",
        week: Some(10),
        profiles: COURSE,
        build: Build::Fixed(weeks::week10_dof),
    },
    BuiltinScene {
        name: "week10-moving",
        summary: "renderMoving: the left sphere moves up by 0.5 (motion blur), jittered, 320x180, 200 spp",
        week: Some(10),
        profiles: COURSE,
        build: Build::Fixed(weeks::week10_moving),
    },
    BuiltinScene {
        name: "rtiow-materials",
        summary: "Ray Tracing in One Weekend: ground, a diffuse centre, hollow glass, fuzzy metal, 400x225, 100 spp",
        week: None,
        profiles: PHYSICAL,
        build: Build::Fixed(rtiow::rtiow_materials),
    },
    BuiltinScene {
        name: "rtiow-defocus",
        summary: "Ray Tracing in One Weekend: the same from (-2, 2, 1), vfov 20, defocus 10 degrees, 100 spp",
        week: None,
        profiles: PHYSICAL,
        build: Build::Fixed(rtiow::rtiow_defocus),
    },
];

/// The built-in scene called `name`, with generated pictures for its image textures.
pub fn builtin(name: &str) -> Result<SceneDescription, SceneError> {
    builtin_with_textures(name, &TextureSource::Generated)
}

/// The built-in scene called `name`, with its image textures from `source`.
pub fn builtin_with_textures(
    name: &str,
    source: &TextureSource,
) -> Result<SceneDescription, SceneError> {
    BUILTIN_SCENES
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| SceneError::Unknown {
            name: name.to_string(),
        })?
        .description_with(source)
}

/// The names of the built-in scenes.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN_SCENES.iter().map(|s| s.name).collect()
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
    /// `defocus_angle = 0`), which the week-4 built-ins (among others) state explicitly.
    #[test]
    fn a_scene_file_may_leave_out_the_book_s_camera_defaults() {
        let defaults = |d: &SceneDescription| {
            (d.camera.up, d.camera.focus_distance, d.camera.defocus_angle)
                == ([0.0, 1.0, 0.0], 10.0, 0.0)
        };
        let with_defaults: Vec<_> = BUILTIN_SCENES
            .iter()
            .filter(|s| defaults(&s.description()))
            .collect();
        assert!(with_defaults.len() >= 4);
        for s in with_defaults {
            let d = s.description();
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

    /// Every built-in validates in each profile it is meant for, and its own profile is the
    /// first of them.
    #[test]
    fn every_builtin_validates_in_its_profiles() {
        for s in BUILTIN_SCENES {
            let own = s.description();
            assert_eq!(Some(&own.profile), s.profiles.first(), "{}", s.name);
            for &profile in s.profiles {
                let d = SceneDescription {
                    profile,
                    ..own.clone()
                };
                d.validate(s.name)
                    .unwrap_or_else(|e| panic!("{} ({profile}): {e}", s.name));
            }
        }
    }

    /// The week-4 scenes' canonical form is what it was before the later weeks' keys existed:
    /// its SHA-256 is the one the checked-in goldens recorded then (`golden/*.exr`'s
    /// `rtoracle.sceneSha256`), so old goldens and caches still match their scenes.
    #[test]
    fn week_4_scenes_keep_their_canonical_form() {
        use sha2::{Digest, Sha256};
        let recorded = [
            (
                "week04-sphere",
                "b82d6234690a8835b89ac0e28a10bf6e45436c3c39fa7ba4f32bd8e2ca04707d",
            ),
            (
                "week04-quad",
                "2bbd032d7c860080ed0abe555e249b302628524cdb197164b197ec2038745f65",
            ),
            (
                "triangles",
                "fde6bd455069ead14143ba196b66252d9be3a0b4841d8e730acbb3497238f6b6",
            ),
            (
                "edge-cases",
                "1857f1c8312d47ed077e17ae1840927e45908187f15125cc253ad0596b0af4a6",
            ),
        ];
        for (name, sha) in recorded {
            let text = builtin(name).unwrap().to_toml();
            let got: String = Sha256::digest(text.as_bytes())
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect();
            assert_eq!(got, sha, "{name}:\n{text}");
        }
    }

    /// The scene of the triangle assignment's rubric (`examples/rubrics/`), written before the
    /// later weeks' keys existed, still loads, as a week-4 scene.
    #[test]
    fn the_example_rubric_scene_still_loads() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/rubrics/triangles-scene.toml");
        let d = SceneDescription::from_file(&path).unwrap();
        assert_eq!(d.render, crate::scene::RenderSettings::default());
        assert_eq!(d.profile, Profile::Course);
        assert!(!d.to_toml().contains("[render]"));
    }

    /// `--textures DIR` takes the course's files by their names (the first stem and extension
    /// found), as absolute paths, and names what it looked for when one is missing.
    #[test]
    fn course_textures_come_from_the_folder_given() {
        let dir = tempfile::tempdir().unwrap();
        let picture = crate::scene::generated_picture("earth").unwrap();
        let png = |name: &str| {
            image::RgbImage::from_raw(
                picture.width as u32,
                picture.height as u32,
                picture.data.clone(),
            )
            .unwrap()
            .save(dir.path().join(name))
            .unwrap()
        };
        png("earthmap.png");
        let source = TextureSource::Folder(dir.path().to_path_buf());
        let e = builtin_with_textures("week07-earth", &source)
            .unwrap_err()
            .to_string();
        assert!(e.contains("basketball.jpg or basketball.png"), "{e}");
        for name in ["basketball.jpg", "soccer.png", "pepsi.jpg"] {
            png(name);
        }
        let d = builtin_with_textures("week07-earth", &source).unwrap();
        let files = d.external_files();
        assert_eq!(files.len(), 4);
        assert!(
            files.iter().all(|f| f.is_absolute())
                && files.iter().any(|f| f.ends_with("earthmap.png"))
                && files.iter().any(|f| f.ends_with("soccer.png")),
            "{files:?}"
        );
        d.validate("t").unwrap();
        // The procedural scene reads no picture.
        assert!(
            builtin_with_textures("week07-procedural-texture", &source)
                .unwrap()
                .external_files()
                .is_empty()
        );
        // Without a folder the generated pictures stand in, and no file is read.
        assert!(builtin("week07-earth").unwrap().external_files().is_empty());
    }
}
