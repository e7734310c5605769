//! The `render` request (`docs/PROTOCOL.md`, "Render requests"): a candidate renders a scene
//! with its own code, tile by tile, and sends back each pixel's mean linear RGB.
//!
//! ```text
//! -> {"sync":true,"id":"render-3","op":"render","scene":{...the scene file as JSON...},
//!     "spp":4,"seed":0,"tile":[0,12,400,16]}
//! <- {"id":"render-3","result":{"tile":[0,12,400,16],"rgb":[0.73,0.84,1.0, ...]}}
//! <- {"id":"render-3","result":{"declined":"RT_material.py has no class Mirror, ..."}}
//! ```
//!
//! [`render_scene`] asks for the image in tiles small enough that each answer fits the
//! protocol's cap on a function's answer ([`MAX_RESULT_BYTES`]), and promises bounds on what
//! comes back whatever the candidate does: an answer of the wrong size (a tile that is not the
//! one asked for, a pixel count that differs), a NaN or infinite value, an error, a death, or no
//! answer within the time left of the job's limit ends the render with the reason, and memory is
//! the image's own size (`3 * width * height` `f32`s) plus one answer line.
//!
//! A job may be a *variant* ([`RenderJob::variant`]): the scene seen from a camera the grader
//! moved ([`CameraMove`]), by an amount the candidate cannot know in advance. Its description is
//! sent already moved, and a program is asked to move its own camera by the same amount (the
//! course adapter does it in `Camera.init_camera`), so that a picture made in advance cannot
//! answer it.
//!
//! A program that raises is the candidate's error: the render ends with it
//! ([`RenderOutcome::Raised`]), it does not fall back to the description.

use std::time::{Duration, Instant};

use serde_json::{Value, json};

use crate::candidate::process::protocol::{CandidateError, MAX_RESULT_BYTES};
use crate::candidate::process::session::{CallOutcome, Session};
use crate::scene::SceneDescription;

/// The longest answer [`render_scene`] plans a tile for: a pixel's three numbers take at most
/// about 3 x 25 bytes in the shortest round-trip syntax, and the tile is sized so that its
/// answer stays under [`MAX_RESULT_BYTES`] with room to spare.
const BYTES_PER_PIXEL: usize = 80;

/// What to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderJob<'a> {
    /// The scene (its camera, image size, objects, materials, settings).
    pub scene: &'a SceneDescription,
    /// Samples per pixel (the scene's own count is ignored).
    pub spp: u32,
    /// A seed the candidate may use for its random numbers (the course adapter does); sent in
    /// every request (grading derives it from the rubric's secret: [`crate::secret`]).
    pub seed: u64,
    /// Wall time the whole render may take, from the first tile's request.
    pub time_limit: Duration,
    /// The candidate's own program that renders this scene (a course `main.py` render
    /// function, `renderMoving`), asked for when its hello lists `"render_program"`: the answer
    /// is then the 8-bit film the program saves. When the program cannot render it (declined,
    /// or an answer of the wrong size), the scene is rendered from its description, and the
    /// image says why ([`MadeBy::DescriptionInstead`]); a program that raises ends the render.
    pub program: Option<&'a str>,
    /// The camera move of a variant: [`scene`](Self::scene) is already seen from the moved
    /// camera, and a program is asked to move its own camera by the same amount (the request's
    /// `"variant"`).
    pub variant: Option<CameraMove>,
}

/// How the grader moved a scene's camera for a variant: added to the camera's `look_from` and
/// `look_at`, its vertical field of view multiplied by `vfov_scale`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CameraMove {
    /// Added to `look_from`.
    pub look_from: [f64; 3],
    /// Added to `look_at`.
    pub look_at: [f64; 3],
    /// The vertical field of view is multiplied by it.
    pub vfov_scale: f64,
}

impl CameraMove {
    /// `scene` seen from the moved camera.
    pub fn apply(&self, scene: &SceneDescription) -> SceneDescription {
        let mut d = scene.clone();
        for k in 0..3 {
            d.camera.look_from[k] += self.look_from[k];
            d.camera.look_at[k] += self.look_at[k];
        }
        d.camera.vfov *= self.vfov_scale;
        d
    }
}

/// How a render was made.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum MadeBy {
    /// The candidate built the scene's description with its own code and sent linear means.
    #[default]
    Description,
    /// The candidate's own program (named) rendered the scene through its own film.
    Program(String),
    /// The job named a program that could not render the scene (why); the description was
    /// rendered instead.
    DescriptionInstead {
        /// The program asked for.
        program: String,
        /// Why it did not render (its decline, its exception, a wrong answer), one line.
        why: String,
    },
}

/// A render that came back whole.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderedImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Samples per pixel it was asked for.
    pub spp: u32,
    /// Wall time it took, in seconds.
    pub seconds: f64,
    /// Mean linear RGB per pixel, row-major, top row first (for a program's film, its codes
    /// decoded as the course's gamma-2 film, for display only: the film is what is judged).
    pub data: Vec<[f32; 3]>,
    /// The 8-bit film the candidate's program saved (3 codes per pixel, row-major, top row
    /// first), when [`made_by`](Self::made_by) is a program: what is judged.
    pub film: Option<Vec<u8>>,
    /// How it was made.
    pub made_by: MadeBy,
}

/// How a render ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderOutcome {
    /// Every tile came back, valid.
    Rendered(RenderedImage),
    /// The candidate does not render, or not this scene: why, in its words or ours.
    Declined(String),
    /// The candidate's code raised (file names are the submission's).
    Raised(CandidateError),
    /// The time limit ran out: how long it was and how many rows had come back.
    TimedOut {
        /// The limit.
        limit: Duration,
        /// Rows rendered before it ran out.
        rows_done: usize,
        /// The image's height.
        height: usize,
    },
    /// An answer broke the render's bounds (wrong size, NaN, malformed) or the candidate died:
    /// what happened.
    Invalid(String),
}

impl RenderOutcome {
    /// Whether an answer broke the protocol (a malformed answer, a key a render answer does not
    /// have): the bundled adapter never does, so a person should look.
    pub fn is_protocol_error(&self) -> bool {
        matches!(self, RenderOutcome::Invalid(why) if why.starts_with("a protocol error"))
    }

    /// One sentence saying why there is no image (`None` for a rendered one).
    pub fn reason(&self) -> Option<String> {
        match self {
            RenderOutcome::Rendered(_) => None,
            RenderOutcome::Declined(why) => Some(format!("the render was declined: {why}")),
            RenderOutcome::Raised(e) => Some(format!("the render raised {e}")),
            RenderOutcome::TimedOut {
                limit,
                rows_done,
                height,
            } => Some(format!(
                "the render did not finish within {} s ({rows_done} of {height} rows done)",
                limit.as_secs_f64()
            )),
            RenderOutcome::Invalid(why) => Some(format!("the render is unusable: {why}")),
        }
    }
}

/// The tiles of a `width` x `height` image, in order: whole rows when a row fits one answer,
/// else pieces of rows. Each is `[x0, y0, x1, y1]` (ends excluded).
pub fn tiles(width: usize, height: usize) -> Vec<[usize; 4]> {
    let per_tile = (MAX_RESULT_BYTES * 3 / 4 / BYTES_PER_PIXEL).max(1);
    let mut out = Vec::new();
    if width == 0 || height == 0 {
        return out;
    }
    if width <= per_tile {
        let rows = (per_tile / width).max(1);
        let mut y = 0;
        while y < height {
            let y1 = (y + rows).min(height);
            out.push([0, y, width, y1]);
            y = y1;
        }
    } else {
        for y in 0..height {
            let mut x = 0;
            while x < width {
                let x1 = (x + per_tile).min(width);
                out.push([x, y, x1, y + 1]);
                x = x1;
            }
        }
    }
    out
}

/// The scene as sent: each image texture carries its picture as `png_hex`, the hex of a PNG
/// of the 8-bit RGB the reference reads (a generated picture, or the file decoded: a JPEG is
/// sent as the reference decodes it), so the candidate reads exactly the golden's texels and
/// needs no file of the grader's. A picture file that cannot be read is why the scene is not
/// sent (a relative file is read from the current folder).
pub fn with_pictures(scene: &SceneDescription, mut value: Value) -> Result<Value, String> {
    let Some(textures) = value.get_mut("textures").and_then(Value::as_array_mut) else {
        return Ok(value);
    };
    for (entry, t) in scene.textures.iter().zip(textures.iter_mut()) {
        if entry.kind != crate::scene::TextureKind::Image {
            continue;
        }
        let picture = match (&entry.generated, &entry.file) {
            (Some(name), _) => crate::scene::generated_picture(name)
                .ok_or_else(|| format!("no generated picture {name:?}"))?,
            (None, Some(file)) => crate::scene::read_picture(std::path::Path::new(file))
                .map_err(|why| format!("the picture {file} of texture {:?}: {why}", entry.name))?,
            (None, None) => continue,
        };
        let png = crate::image_io::encode_png(&crate::image_io::Rgb8Image {
            width: picture.width,
            height: picture.height,
            data: picture.data,
        })?;
        let hex: String = png.iter().map(|b| format!("{b:02x}")).collect();
        if let Some(obj) = t.as_object_mut() {
            obj.insert("png_hex".into(), Value::String(hex));
        }
    }
    Ok(value)
}

/// The request for one tile, without its id (the session adds it).
pub fn render_request(job: &RenderJob, scene: &Value, tile: [usize; 4]) -> Value {
    let mut request = json!({
        "op": "render",
        "scene": scene,
        "spp": job.spp,
        "seed": job.seed,
        "tile": tile,
    });
    if let Some(program) = job.program {
        request["program"] = json!(program);
        if let Some(v) = &job.variant {
            request["variant"] = json!(v);
        }
    }
    request
}

/// A number of an answer: a JSON number, or `"nan"`, `"inf"`, `"-inf"` as strings.
fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => match s.as_str() {
            "nan" => Some(f64::NAN),
            "inf" => Some(f64::INFINITY),
            "-inf" => Some(f64::NEG_INFINITY),
            _ => None,
        },
        _ => None,
    }
}

/// Reads one tile's answer into `data` (the whole image, `width` x `height`); `Err` says what
/// is wrong with it, naming the first bad pixel. An answer may say the `size` of the image its
/// camera makes (the course adapter does): another size than the scene's is wrong.
pub fn read_tile(
    result: &Value,
    tile: [usize; 4],
    (width, height): (usize, usize),
    data: &mut [[f32; 3]],
) -> Result<(), String> {
    read_header(result, tile, (width, height))?;
    let [x0, y0, x1, y1] = tile;
    let Some(rgb) = result.get("rgb").and_then(Value::as_array) else {
        return Err(format!(
            "the answer for the tile x {x0}..{x1}, y {y0}..{y1} has no \"rgb\" list"
        ));
    };
    let pixels = (x1 - x0) * (y1 - y0);
    if rgb.len() != 3 * pixels {
        return Err(format!(
            "the tile x {x0}..{x1}, y {y0}..{y1} has {} numbers, not 3 x {pixels} (the image is {width} pixels wide)",
            rgb.len()
        ));
    }
    for (k, triple) in rgb.chunks(3).enumerate() {
        let (x, y) = (x0 + k % (x1 - x0), y0 + k / (x1 - x0));
        let mut px = [0f32; 3];
        for (c, v) in triple.iter().enumerate() {
            let Some(n) = number(v) else {
                return Err(format!("pixel ({x}, {y}) is not a number: {}", {
                    crate::escape::truncate(&v.to_string(), 40)
                }));
            };
            if !n.is_finite() || !(n as f32).is_finite() {
                return Err(format!(
                    "pixel ({x}, {y}) is {} (a colour must be a finite number)",
                    if n.is_nan() {
                        "NaN".to_string()
                    } else {
                        n.to_string()
                    }
                ));
            }
            px[c] = n as f32;
        }
        data[y * width + x] = px;
    }
    Ok(())
}

/// Reads one tile of a program's answer (`"film"`: 8-bit codes, 3 per pixel) into `film` (the
/// whole image's codes) and, decoded as the course's gamma-2 film (the middle of each code,
/// squared), into `data`; `Err` says what is wrong, naming the first bad pixel.
pub fn read_film_tile(
    result: &Value,
    tile: [usize; 4],
    (width, height): (usize, usize),
    data: &mut [[f32; 3]],
    film: &mut [u8],
) -> Result<(), String> {
    read_header(result, tile, (width, height))?;
    let [x0, y0, x1, y1] = tile;
    let Some(codes) = result.get("film").and_then(Value::as_array) else {
        return Err(format!(
            "the answer for the tile x {x0}..{x1}, y {y0}..{y1} has no \"film\" list"
        ));
    };
    let pixels = (x1 - x0) * (y1 - y0);
    if codes.len() != 3 * pixels {
        return Err(format!(
            "the tile x {x0}..{x1}, y {y0}..{y1} has {} codes, not 3 x {pixels}",
            codes.len()
        ));
    }
    for (k, triple) in codes.chunks(3).enumerate() {
        let (x, y) = (x0 + k % (x1 - x0), y0 + k / (x1 - x0));
        let at = y * width + x;
        for (c, v) in triple.iter().enumerate() {
            let Some(code) = v.as_u64().and_then(|n| u8::try_from(n).ok()) else {
                return Err(format!(
                    "pixel ({x}, {y}) is not an 8-bit code: {}",
                    crate::escape::truncate(&v.to_string(), 40)
                ));
            };
            film[3 * at + c] = code;
            // The course's film is gamma 2 over 255 codes: the middle of the code, squared.
            let g = (f64::from(code) + 0.5) / 255.0;
            data[at][c] = (g * g).min(1.0) as f32;
        }
    }
    Ok(())
}

/// Checks that an answer is for `tile` and, when it says the size of its image, that the size is
/// the scene's.
fn read_header(
    result: &Value,
    tile: [usize; 4],
    (width, height): (usize, usize),
) -> Result<(), String> {
    let [x0, y0, x1, y1] = tile;
    let echoed: Option<Vec<u64>> = result
        .get("tile")
        .and_then(Value::as_array)
        .map(|a| a.iter().filter_map(Value::as_u64).collect());
    if echoed.as_deref() != Some(&[x0 as u64, y0 as u64, x1 as u64, y1 as u64][..]) {
        return Err(format!(
            "the answer for the tile x {x0}..{x1}, y {y0}..{y1} names another tile ({})",
            result.get("tile").map_or("none".into(), |t| {
                crate::escape::truncate(&t.to_string(), 80)
            })
        ));
    }
    if let Some(size) = result.get("size") {
        let made: Option<Vec<u64>> = size
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_u64).collect());
        let want = [width as u64, height as u64];
        if made.as_deref() != Some(&want[..]) {
            return Err(format!(
                "the candidate's camera makes an image of size {} but the scene is {width}x{height}",
                crate::escape::truncate(&size.to_string(), 40)
            ));
        }
    }
    Ok(())
}

/// Renders `job` through `session`, tile by tile (see the module docs); the candidate must list
/// `"render"` among its hello's `ops`, else the render is declined without a request. A job
/// naming a [`program`](RenderJob::program) is first asked of the program when the hello lists
/// `"render_program"`; if the program does not render it (declined, raised, an answer of the
/// wrong size or form), the scene's description is rendered within the time left, and the image
/// says why. A program that runs out of time is the render's time-out.
pub fn render_scene(session: &mut Session, job: &RenderJob) -> RenderOutcome {
    if session.hello().error.is_none() && !session.hello().answers("render") {
        return RenderOutcome::Declined(
            "the candidate's hello does not list \"render\" among its ops".into(),
        );
    }
    let start = Instant::now();
    let Some(program) = job.program else {
        return render_tiles(session, job, start, None);
    };
    let why = if session.hello().answers("render_program") {
        match render_tiles(session, job, start, Some(program)) {
            done @ (RenderOutcome::Rendered(_)
            | RenderOutcome::TimedOut { .. }
            | RenderOutcome::Raised(_)) => return done,
            failed => failed.reason().unwrap_or_default(),
        }
    } else {
        "the candidate does not run its own program (its hello does not list \"render_program\")"
            .to_string()
    };
    match render_tiles(session, job, start, None) {
        RenderOutcome::Rendered(mut image) => {
            image.made_by = MadeBy::DescriptionInstead {
                program: program.to_string(),
                why: crate::escape::truncate(&why, 300),
            };
            RenderOutcome::Rendered(image)
        }
        other => other,
    }
}

/// Renders `job` from its description, or by `program` (its film), every tile, within the job's
/// time limit counted from `start`.
fn render_tiles(
    session: &mut Session,
    job: &RenderJob,
    start: Instant,
    program: Option<&str>,
) -> RenderOutcome {
    let camera = job.scene.camera(None);
    let (width, height) = (camera.width, camera.height);
    let scene = match serde_json::to_value(job.scene) {
        Ok(v) => v,
        Err(e) => return RenderOutcome::Invalid(format!("the scene cannot be sent: {e}")),
    };
    let scene = match with_pictures(job.scene, scene) {
        Ok(v) => v,
        Err(why) => return RenderOutcome::Declined(why),
    };
    let asked = RenderJob { program, ..*job };
    let deadline = start + job.time_limit;
    let mut data = vec![[0f32; 3]; width * height];
    let mut film = program.map(|_| vec![0u8; 3 * width * height]);
    let mut rows_done = 0;
    for (k, tile) in tiles(width, height).into_iter().enumerate() {
        let left = deadline.saturating_duration_since(Instant::now());
        let timed_out = RenderOutcome::TimedOut {
            limit: job.time_limit,
            rows_done,
            height,
        };
        if left.is_zero() {
            return timed_out;
        }
        let request = render_request(&asked, &scene, tile);
        match session.call(&format!("render-{k}"), &request, left) {
            CallOutcome::Result(result) => {
                if let Some(why) = unknown_render_key(&result) {
                    return RenderOutcome::Invalid(why);
                }
                if let Some(why) = result.get("declined") {
                    let why = why.as_str().map_or_else(|| why.to_string(), str::to_string);
                    return RenderOutcome::Declined(crate::escape::truncate(&why, 400));
                }
                let read = match film.as_deref_mut() {
                    Some(film) => read_film_tile(&result, tile, (width, height), &mut data, film),
                    None => read_tile(&result, tile, (width, height), &mut data),
                };
                if let Err(why) = read {
                    return RenderOutcome::Invalid(why);
                }
                if tile[2] == width {
                    rows_done = tile[3];
                }
            }
            CallOutcome::Error(e) => return RenderOutcome::Raised(e),
            CallOutcome::TimedOut => return timed_out,
            CallOutcome::Protocol(why) => {
                return RenderOutcome::Invalid(format!("a protocol error: {why}"));
            }
            CallOutcome::Failed(why) => {
                if Instant::now() >= deadline {
                    return timed_out;
                }
                return RenderOutcome::Invalid(why);
            }
        }
    }
    RenderOutcome::Rendered(RenderedImage {
        width,
        height,
        spp: job.spp,
        seconds: start.elapsed().as_secs_f64(),
        data,
        made_by: program.map_or(MadeBy::Description, |p| MadeBy::Program(p.to_string())),
        film,
    })
}

/// The keys a render answer's `result` may hold (docs/PROTOCOL.md, "Render requests").
pub const RENDER_KEYS: [&str; 5] = ["tile", "size", "rgb", "film", "declined"];

/// A protocol error when a render answer's `result` is not an object or holds a key
/// [`RENDER_KEYS`] does not name.
fn unknown_render_key(result: &serde_json::Value) -> Option<String> {
    let Some(map) = result.as_object() else {
        return Some("a protocol error: the render answer's \"result\" is not an object".into());
    };
    map.keys().find(|k| !RENDER_KEYS.contains(&k.as_str())).map(|k| {
        format!(
            "a protocol error: the render answer has the key \"{}\", which it does not have (its keys: {})",
            crate::escape::truncate(k, 60),
            RENDER_KEYS.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once_and_fit_an_answer() {
        for (w, h) in [(400, 225), (400, 400), (1, 1), (5000, 3), (7, 1000)] {
            let mut seen = vec![0u8; w * h];
            for [x0, y0, x1, y1] in tiles(w, h) {
                assert!(x0 < x1 && y0 < y1 && x1 <= w && y1 <= h);
                assert!((x1 - x0) * (y1 - y0) * BYTES_PER_PIXEL <= MAX_RESULT_BYTES);
                for y in y0..y1 {
                    for x in x0..x1 {
                        seen[y * w + x] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{w}x{h}");
        }
        assert!(tiles(0, 5).is_empty());
    }

    /// The answer of a pixel at the worst length the course adapter writes (`repr` of a float
    /// with 17 digits and an exponent) fits the plan of [`BYTES_PER_PIXEL`].
    #[test]
    fn the_longest_numbers_fit_the_tile_plan() {
        let worst = format!("{:?},", -1.2345678901234567e-300f64);
        assert!(3 * worst.len() <= BYTES_PER_PIXEL, "{worst}");
    }

    #[test]
    fn answers_of_the_wrong_size_or_with_nan_are_refused_naming_the_pixel() {
        let mut data = vec![[0f32; 3]; 4];
        let good = json!({"tile": [0, 1, 2, 2], "rgb": [0.5, 0.25, 1, 0, 0, "inf"]});
        let e = read_tile(&good, [0, 1, 2, 2], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("pixel (1, 1) is inf"), "{e}");
        let ok = json!({"tile": [0, 1, 2, 2], "rgb": [0.5, 0.25, 1, 0, 0, 2]});
        read_tile(&ok, [0, 1, 2, 2], (2, 2), &mut data).unwrap();
        assert_eq!(data[2], [0.5, 0.25, 1.0]);
        assert_eq!(data[3], [0.0, 0.0, 2.0]);
        let nan = json!({"tile": [0, 0, 2, 1], "rgb": [0, 0, 0, 0, "nan", 0]});
        let e = read_tile(&nan, [0, 0, 2, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("pixel (1, 0) is NaN"), "{e}");
        let short = json!({"tile": [0, 0, 2, 1], "rgb": [0, 0, 0]});
        let e = read_tile(&short, [0, 0, 2, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("has 3 numbers, not 3 x 2"), "{e}");
        let other = json!({"tile": [0, 0, 1, 1], "rgb": [0, 0, 0]});
        let e = read_tile(&other, [0, 0, 2, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("names another tile"), "{e}");
        let word = json!({"tile": [0, 0, 1, 1], "rgb": [0, "x", 0]});
        let e = read_tile(&word, [0, 0, 1, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("pixel (0, 0) is not a number"), "{e}");
        let sized = json!({"tile": [0, 0, 1, 1], "size": [2, 3], "rgb": [0, 0, 0]});
        let e = read_tile(&sized, [0, 0, 1, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("size [2,3] but the scene is 2x2"), "{e}");
        let right = json!({"tile": [0, 0, 1, 1], "size": [2, 2], "rgb": [0, 0, 0]});
        read_tile(&right, [0, 0, 1, 1], (2, 2), &mut data).unwrap();
        let huge = json!({"tile": [0, 0, 1, 1], "rgb": [0, 1e300, 0]});
        let e = read_tile(&huge, [0, 0, 1, 1], (2, 2), &mut data).unwrap_err();
        assert!(e.contains("finite"), "{e}");
    }

    #[test]
    fn film_answers_hold_8_bit_codes_and_decode_as_the_course_film_encodes() {
        let mut data = vec![[0f32; 3]; 4];
        let mut film = vec![0u8; 12];
        let ok = json!({"tile": [0, 1, 2, 2], "size": [2, 2], "film": [0, 128, 255, 1, 2, 3]});
        read_film_tile(&ok, [0, 1, 2, 2], (2, 2), &mut data, &mut film).unwrap();
        assert_eq!(&film[6..], &[0, 128, 255, 1, 2, 3]);
        assert_eq!(&film[..6], &[0; 6], "rows outside the tile stay untouched");
        // Gamma 2 over 255 codes: a code stands for the middle of its interval, squared.
        let middle = |code: f64| (((code + 0.5) / 255.0) * ((code + 0.5) / 255.0)) as f32;
        assert_eq!(data[2], [middle(0.0), middle(128.0), 1.0]);
        assert_eq!(data[3], [middle(1.0), middle(2.0), middle(3.0)]);
        let refused = [
            (json!([0, 256, 0]), "pixel (0, 0) is not an 8-bit code: 256"),
            (json!([0, 0, -1]), "pixel (0, 0) is not an 8-bit code: -1"),
            (json!([1.5, 0, 0]), "pixel (0, 0) is not an 8-bit code: 1.5"),
            (json!(["7", 0, 0]), "is not an 8-bit code"),
            (json!([0, 0]), "has 2 codes, not 3 x 1"),
            (json!([0, 0, 0, 0]), "has 4 codes, not 3 x 1"),
        ];
        for (codes, said) in refused {
            let answer = json!({"tile": [0, 0, 1, 1], "film": codes});
            let e =
                read_film_tile(&answer, [0, 0, 1, 1], (2, 2), &mut data, &mut film).unwrap_err();
            assert!(e.contains(said), "{codes}: {e}");
        }
        let linear = json!({"tile": [0, 0, 1, 1], "rgb": [0, 0, 0]});
        let e = read_film_tile(&linear, [0, 0, 1, 1], (2, 2), &mut data, &mut film).unwrap_err();
        assert!(e.contains("has no \"film\" list"), "{e}");
        let sized = json!({"tile": [0, 0, 1, 1], "size": [3, 2], "film": [0, 0, 0]});
        let e = read_film_tile(&sized, [0, 0, 1, 1], (2, 2), &mut data, &mut film).unwrap_err();
        assert!(e.contains("but the scene is 2x2"), "{e}");
    }
}
