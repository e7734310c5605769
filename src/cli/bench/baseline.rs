//! The C baseline of `rtoracle bench render`: `benches/baseline.c`, a plain C loop doing the
//! reference tracer's work one ray at a time, built here as a shared library with the system's
//! C compiler and loaded into this process.
//!
//! It is loaded rather than run as a program so that it can call the reference's own `pow`
//! (the `libm` crate's, which rounds differently from the C library's on about 10% of the
//! arguments week 8 can meet): the same function on the same arguments, so the two films can be compared bit for
//! bit. `libloading` does the loading (the maintained wrapper of `dlopen`, rather than our own
//! calls into `libc`).
//!
//! [`CScene::of`] writes a world and camera into the structs `baseline.c` declares (the two
//! must be kept in step), and refuses, with the reason, what the C loop does not render.

use std::time::Duration;

use glam::DVec3;
use rtoracle::render::Film;
use rtoracle::scene::{
    Background, Camera, DiffuseSampling, DirectTerm, Integrator, Material, Object, PixelSampling,
    Profile, Texture, World,
};

use super::{process_cpu_time, spawn_killed_on_interrupt};

/// The C baseline's source, built into the binary so the benchmark runs anywhere.
const BASELINE_C: &str = include_str!("../../../benches/baseline.c");

/// `bl_object`: a sphere (`a` its centre) or a quad (`a` its corner, `u` and `v` its sides).
#[repr(C)]
struct CObject {
    kind: i32,
    material: i32,
    a: [f64; 3],
    radius: f64,
    u: [f64; 3],
    v: [f64; 3],
}

/// `bl_material`: `colour` is the albedo, a light's emission or the checker's even colour.
#[repr(C)]
struct CMaterial {
    kind: i32,
    unused: i32,
    colour: [f64; 3],
    odd: [f64; 3],
    scale: f64,
    ior: f64,
    kd: f64,
    ks: f64,
    alpha: f64,
}

/// `bl_scene`.
#[repr(C)]
struct CSceneHeader {
    objects: *const CObject,
    n_objects: i32,
    n_materials: i32,
    materials: *const CMaterial,
    integrator: i32,
    max_depth: i32,
    sky: i32,
    width: i32,
    height: i32,
    unused: i32,
    background: [f64; 3],
    center: [f64; 3],
    pixel00: [f64; 3],
    du: [f64; 3],
    dv: [f64; 3],
    pow: extern "C" fn(f64, f64) -> f64,
}

/// The reference's `pow`, for the C loop to call where the reference does.
extern "C" fn reference_pow(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// A scene as the C loop reads it: the objects and materials, and what the header points at.
pub(super) struct CScene {
    objects: Vec<CObject>,
    materials: Vec<CMaterial>,
    integrator: i32,
    max_depth: i32,
    background: Option<[f64; 3]>,
    camera: Camera,
}

impl CScene {
    /// `world` seen by `camera`, or why the C loop cannot render it the same way.
    pub(super) fn of(world: &World, camera: &Camera) -> Result<Self, String> {
        let s = &world.settings;
        let refuse = |what: &str| Err(format!("the C loop does not render {what}"));
        if world.profile != Profile::Course {
            return refuse("the physical profile");
        }
        if s.sampling != PixelSampling::Uniform || s.diffuse_sampling != DiffuseSampling::UnitSphere
        {
            return refuse("jittered pixels or cosine sampling");
        }
        if s.integrator == Integrator::Direct && s.direct_term != DirectTerm::Clamped {
            return refuse("the unclamped direct term");
        }
        if s.integrator == Integrator::Brdf && !s.direct_light {
            return refuse("the BRDF integrator without direct light");
        }
        if camera.defocus || world.moving || world.has_hierarchy() {
            return refuse("defocus, motion or a bounding volume hierarchy");
        }
        let materials = world
            .materials
            .iter()
            .map(c_material)
            .collect::<Result<Vec<_>, _>>()?;
        let mut objects = Vec::with_capacity(world.objects.len());
        for o in &world.objects {
            let material = i32::try_from(o.material).map_err(|_| "too many materials")?;
            objects.push(match o.shape {
                Object::Sphere(sphere) => CObject {
                    kind: 0,
                    material,
                    a: sphere.center.to_array(),
                    radius: sphere.radius,
                    u: [0.0; 3],
                    v: [0.0; 3],
                },
                Object::Quad(quad) => CObject {
                    kind: 1,
                    material,
                    a: quad.q.to_array(),
                    radius: 0.0,
                    u: quad.u.to_array(),
                    v: quad.v.to_array(),
                },
                _ => return refuse("moving spheres or triangles"),
            });
        }
        if world.point_lights.len() > 64 {
            return refuse("more than 64 point lights");
        }
        Ok(Self {
            objects,
            materials,
            integrator: match s.integrator {
                Integrator::Albedo => 0,
                Integrator::Direct => 1,
                Integrator::Brdf => 2,
            },
            max_depth: i32::try_from(s.max_depth).unwrap_or(i32::MAX),
            background: match s.background {
                Background::Sky => None,
                Background::Flat => Some(s.background_color),
            },
            camera: *camera,
        })
    }
}

/// The C loop's material for `m`, or why it has none.
fn c_material(m: &Material) -> Result<CMaterial, String> {
    let base = |kind: i32, colour: DVec3| CMaterial {
        kind,
        unused: 0,
        colour: colour.to_array(),
        odd: [0.0; 3],
        scale: 1.0,
        ior: 1.0,
        kd: 0.0,
        ks: 0.0,
        alpha: 0.0,
    };
    Ok(match *m {
        Material::Lambertian { albedo } => base(0, albedo),
        Material::Textured {
            texture: Texture::Solid(c),
        } => base(0, c),
        Material::Textured {
            texture: Texture::Checker { scale, even, odd },
        } => CMaterial {
            odd: odd.to_array(),
            scale,
            ..base(6, even)
        },
        Material::Mirror { albedo } => base(1, albedo),
        Material::Dielectric { albedo, ior } => CMaterial {
            ior,
            ..base(2, albedo)
        },
        Material::DiffuseLight { emit } => base(3, emit),
        Material::Phong {
            albedo,
            kd,
            ks,
            alpha,
        }
        | Material::Blinn {
            albedo,
            kd,
            ks,
            alpha,
        } => CMaterial {
            kd,
            ks,
            alpha,
            ..base(
                if matches!(m, Material::Phong { .. }) {
                    4
                } else {
                    5
                },
                albedo,
            )
        },
        _ => {
            return Err("the C loop does not render image textures, metal or Cook-Torrance".into());
        }
    })
}

/// `rtoracle_baseline_render(scene, spp, seed, film)`.
type RenderFn = unsafe extern "C" fn(*const CSceneHeader, u32, u64, *mut f64) -> i32;

/// The built and loaded C loop; the folder it was built in goes when this does.
pub(super) struct CBaseline {
    library: libloading::Library,
    _dir: tempfile::TempDir,
    /// Removes the folder if the benchmark is interrupted.
    _dir_guard: rtoracle::interrupt::CleanupGuard,
}

impl CBaseline {
    /// Builds `benches/baseline.c` with `cc -O3 -ffp-contract=off` (no fused multiply-adds, as
    /// the reference has none) into a shared library and loads it; `Err` says why it could not.
    pub(super) fn build(cc: &str) -> Result<Self, String> {
        let (dir, dir_guard) =
            rtoracle::interrupt::create_temporary(tempfile::tempdir, |d| d.path())
                .map_err(|e| format!("cannot make a temporary folder: {e}"))?;
        let source = dir.path().join("baseline.c");
        let library = dir.path().join("libbaseline.so");
        std::fs::write(&source, BASELINE_C).map_err(|e| format!("cannot write the source: {e}"))?;
        let mut command = std::process::Command::new(cc);
        command
            .args(["-O3", "-ffp-contract=off", "-shared", "-fPIC", "-o"])
            .arg(&library)
            .arg(&source)
            .arg("-lm")
            // The compiler's own temporary files go into the folder, removed with it.
            .env("TMPDIR", dir.path())
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped());
        let (child, _kill) = spawn_killed_on_interrupt(&mut command)
            .map_err(|e| format!("no C compiler '{cc}' ({})", e.root_cause()))?;
        let compiled = child
            .wait_with_output()
            .map_err(|e| format!("cannot wait for '{cc}': {e}"))?;
        if !compiled.status.success() {
            let stderr = String::from_utf8_lossy(&compiled.stderr);
            return Err(format!(
                "'{cc}' could not build it: {}",
                stderr.lines().next().unwrap_or("no message")
            ));
        }
        // SAFETY: the library is the one just built from `benches/baseline.c`, which has no
        // initialisers and defines nothing that clashes with this process's symbols.
        let library = unsafe { libloading::Library::new(&library) }
            .map_err(|e| format!("cannot load what '{cc}' built: {e}"))?;
        Ok(Self {
            library,
            _dir: dir,
            _dir_guard: dir_guard,
        })
    }

    /// Renders `scene` at `spp` with `seed` on this thread: the film's means (row-major, three
    /// channels a pixel) and the process's CPU time it took.
    pub(super) fn render(
        &self,
        scene: &CScene,
        spp: u32,
        seed: u64,
    ) -> Result<(Vec<f64>, Duration), String> {
        let camera = &scene.camera;
        let (width, height) = (camera.width, camera.height);
        let size = |n: usize| i32::try_from(n).map_err(|_| format!("{n} is too large for C"));
        let header = CSceneHeader {
            objects: scene.objects.as_ptr(),
            n_objects: size(scene.objects.len())?,
            n_materials: size(scene.materials.len())?,
            materials: scene.materials.as_ptr(),
            integrator: scene.integrator,
            max_depth: scene.max_depth,
            sky: i32::from(scene.background.is_none()),
            width: size(width)?,
            height: size(height)?,
            unused: 0,
            background: scene.background.unwrap_or([0.0; 3]),
            center: camera.center.to_array(),
            pixel00: camera.pixel00.to_array(),
            du: camera.pixel_delta_u.to_array(),
            dv: camera.pixel_delta_v.to_array(),
            pow: reference_pow,
        };
        let mut film = vec![0.0f64; width * height * 3];
        // SAFETY: the symbol is `baseline.c`'s `rtoracle_baseline_render`, of this type.
        let render: libloading::Symbol<'_, RenderFn> =
            unsafe { self.library.get(b"rtoracle_baseline_render\0") }
                .map_err(|e| format!("the library has no render function: {e}"))?;
        let start = process_cpu_time();
        // SAFETY: `header` points at `scene`'s vectors, alive for the call, with the counts
        // given; `film` holds width x height x 3 doubles, what the function writes.
        let status = unsafe { render(&header, spp, seed, film.as_mut_ptr()) };
        let cpu = process_cpu_time().saturating_sub(start);
        match status {
            0 => Ok((film, cpu)),
            2 => Err("the C loop ran out of memory".into()),
            _ => Err("the C loop refused the scene".into()),
        }
    }
}

/// How many of `film`'s pixels differ, in any bit of any channel, from the C loop's `means`.
pub(super) fn pixels_differing(film: &Film, means: &[f64]) -> usize {
    film.mean
        .iter()
        .zip(means.chunks_exact(3))
        .filter(|(m, c)| {
            m.to_array()
                .iter()
                .zip(c.iter())
                .any(|(a, b)| a.to_bits() != b.to_bits())
        })
        .count()
        + film.mean.len().abs_diff(means.len() / 3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtoracle::render::{RenderOptions, render};

    /// The C loop, or `None` (said on stderr) where this machine has no C compiler.
    fn c_loop() -> Option<CBaseline> {
        match CBaseline::build("cc") {
            Ok(c) => Some(c),
            Err(why) => {
                eprintln!("SKIPPED: no C baseline here ({why})");
                None
            }
        }
    }

    /// Two programs written apart, the reference and `benches/baseline.c`, render every built-in
    /// scene the C loop accepts to the same film, bit for bit, at 3 spp and two seeds: the
    /// direct term with quads and point lights (week 5), mirrors and glass (week 6), Phong and
    /// Blinn with a checker ground (week 8), week 4's colours. And the C loop accepts at least
    /// those, and refuses the rest.
    #[test]
    fn the_c_loop_renders_the_references_film_on_every_scene_it_accepts() {
        let Some(c) = c_loop() else { return };
        let mut accepted = Vec::new();
        for name in rtoracle::scene::builtin_names() {
            let description = rtoracle::scene::builtin(name).unwrap();
            let (world, camera) = (description.scene(), description.camera(Some(96)));
            let Ok(scene) = CScene::of(&world, &camera) else {
                continue;
            };
            for seed in [0, 7] {
                let options = RenderOptions {
                    samples_per_pixel: 3,
                    seed,
                    ..Default::default()
                };
                let film = render(&world, &camera, &options).unwrap();
                let (means, _) = c.render(&scene, 3, seed).unwrap();
                assert_eq!(pixels_differing(&film, &means), 0, "{name}, seed {seed}");
            }
            accepted.push(name);
        }
        eprintln!("the C loop rendered the reference's films of {accepted:?}");
        for name in [
            "week04-sphere",
            "week05-quad-light",
            "week05-point-light-shadow",
            "week06-mirror-point-light",
            "week06-dielectric",
            "week08-phong",
            "week08-blinn",
        ] {
            assert!(
                accepted.contains(&name),
                "{name} not accepted: {accepted:?}"
            );
        }
    }

    /// What the C loop does not render is refused with the reason, before any work.
    #[test]
    fn what_the_c_loop_does_not_render_is_refused() {
        for (name, reason) in [
            ("week07-earth", "image textures, metal"),
            ("week09-blinn", "jittered pixels"),
            ("week10-moving", "jittered pixels"),
            ("rtiow-materials", "physical profile"),
        ] {
            let d = rtoracle::scene::builtin(name).unwrap();
            let Err(why) = CScene::of(&d.scene(), &d.camera(None)) else {
                panic!("{name} accepted");
            };
            assert!(why.contains(reason), "{name}: {why}");
        }
    }

    /// A film that differs from the C loop's in one bit of one channel of one pixel, or in its
    /// size, is counted.
    #[test]
    fn one_bit_of_difference_is_counted() {
        let film = Film {
            width: 2,
            height: 1,
            samples_per_pixel: 1,
            mean: vec![DVec3::new(0.5, 0.25, 1.0), DVec3::splat(0.1)],
            variance: None,
            deviation: None,
        };
        let mut means = vec![0.5, 0.25, 1.0, 0.1, 0.1, 0.1];
        assert_eq!(pixels_differing(&film, &means), 0);
        means[4] = f64::from_bits(0.1f64.to_bits() + 1);
        assert_eq!(pixels_differing(&film, &means), 1);
        assert_eq!(pixels_differing(&film, &means[..3]), 1);
    }
}
