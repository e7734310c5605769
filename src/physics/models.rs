//! rtoracle's own materials answering the protocol's material requests, in Rust: the book's
//! (*Ray Tracing in One Weekend*'s Lambertian, metal, dielectric and mirror, with their exact
//! pdfs), the course's BRDF materials as its integrator applies them (weeks 8 and 9), and the
//! catalogued material mistakes ([`Mistake`]).
//!
//! They serve twice. As the **reference** of a law: when a candidate breaks a law that rtoracle's
//! transcription of the same model breaks too (the course's Phong with `kd + ks > 1` gains
//! energy, the book's fuzzy metal is not reciprocal), the report calls it a finding about the
//! model, not the candidate's failure. And as **test subjects**: the checks' false-alarm rate on
//! the honest models and their power against each mistake are measured over many seeds in
//! process ([`ModelSource`]), with no adapter.
//!
//! Conventions (the protocol's): `wo` and `wi` are unit vectors pointing away from the surface
//! point; `n` is the unit normal (outward); a sample's `weight` is what a path's throughput is
//! multiplied by, `f |cos theta_i| / pdf` for an honest sampler.

use std::f64::consts::PI;

use glam::DVec3;

use super::source::{MaterialSample, MaterialSource, Op, Problem};
use crate::render as brdf;
use crate::render::{Onb, reflect, schlick};

/// Whose version of a material type answers: the book's physically based ones, or the course's
/// as its BRDF integrator applies them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// *Ray Tracing in One Weekend*'s materials, with their exact pdfs.
    Book,
    /// The course's week-8 and week-9 materials: directions from `scattering`, the weight
    /// `BRDF(view, light) c(n . d)` of its integrator (no pdf). `cosine`: week 9's
    /// cosine-hemisphere sampling through the ONB; otherwise week 8's `n + random_vec3_unit()`.
    Course {
        /// Week 9's sampling (the cosine lobe through the ONB).
        cosine: bool,
    },
}

/// A catalogued material mistake (each a model of its own, named as the docs name it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mistake {
    /// A Lambertian whose pdf is `1 / pi`: the cosine forgotten.
    PdfMissingCosine,
    /// A Lambertian sampling the hemisphere uniformly but reporting the cosine pdf.
    UniformWithCosinePdf,
    /// A Lambertian whose weight is `f cos` (not divided by the pdf).
    WeightNotDivided,
    /// A dielectric that refracts where it must reflect (no total internal reflection).
    NoTotalInternalReflection,
    /// A Lambertian whose BRDF is the albedo (the `1 / pi` forgotten): it reflects `pi` times
    /// what it receives.
    EnergyGain,
    /// A Lambertian darkened by the Fresnel factor of the incoming side only:
    /// `f = albedo (1 - F(cos theta_i)) / pi`, not symmetric in `wo` and `wi`.
    NonReciprocal,
}

impl Mistake {
    /// Every mistake of the catalogue.
    pub const ALL: [Mistake; 6] = [
        Mistake::PdfMissingCosine,
        Mistake::UniformWithCosinePdf,
        Mistake::WeightNotDivided,
        Mistake::NoTotalInternalReflection,
        Mistake::EnergyGain,
        Mistake::NonReciprocal,
    ];

    /// The catalogue's name.
    pub fn name(self) -> &'static str {
        match self {
            Mistake::PdfMissingCosine => "pdf_missing_cosine",
            Mistake::UniformWithCosinePdf => "uniform_with_cosine_pdf",
            Mistake::WeightNotDivided => "weight_not_divided",
            Mistake::NoTotalInternalReflection => "no_total_internal_reflection",
            Mistake::EnergyGain => "energy_gain",
            Mistake::NonReciprocal => "non_reciprocal",
        }
    }

    /// The material type the mistake replaces.
    pub fn material_type(self) -> &'static str {
        match self {
            Mistake::NoTotalInternalReflection => "dielectric",
            _ => "lambertian",
        }
    }

    /// The laws whose checks catch it (any one of them): a dielectric that refracts under total
    /// internal reflection with the book's `sqrt(|1 - |perp|^2|)` returns a direction that is
    /// not a unit vector (an invalid sample); one that normalises it breaks Snell's law.
    pub fn caught_by(self) -> &'static [&'static str] {
        match self {
            Mistake::PdfMissingCosine => &["pdf_integral"],
            Mistake::UniformWithCosinePdf => &["distribution"],
            Mistake::WeightNotDivided => &["weight"],
            Mistake::NoTotalInternalReflection => &["samples", "delta_law"],
            Mistake::EnergyGain => &["energy"],
            Mistake::NonReciprocal => &["reciprocity"],
        }
    }
}

/// One material as a model: its parameters read from the protocol's description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// The book's `lambertian`: `n + random_unit_vector()`, weight the albedo, pdf `cos / pi`.
    Lambertian {
        /// Albedo.
        albedo: DVec3,
    },
    /// The book's `metal`: `unit(reflect) + fuzz random_unit_vector()`, normalised; absorbed
    /// below the surface; weight the albedo. A delta when `fuzz = 0`.
    Metal {
        /// Albedo.
        albedo: DVec3,
        /// Fuzz (the protocol's `roughness`), at most 1.
        fuzz: f64,
    },
    /// The book's `dielectric`: reflect with Schlick's probability (always under total internal
    /// reflection), else refract; weight the albedo (white in the book).
    Dielectric {
        /// Attenuation.
        albedo: DVec3,
        /// Index of refraction, inside over outside.
        ior: f64,
    },
    /// A perfect mirror: a delta, weight the albedo.
    Mirror {
        /// Albedo.
        albedo: DVec3,
    },
    /// The course's BRDF material of week 8 or 9 (`Lambertian`, `Phong`, `Blinn`,
    /// `CookTorrance`): directions from its `scattering`, weight `BRDF c(n . d)`, no pdf.
    Course {
        /// The course's BRDF.
        brdf: CourseBrdf,
        /// Week 9's cosine sampling (else week 8's `n + u`).
        cosine: bool,
    },
    /// A catalogued mistake with its base material's albedo (and index of refraction).
    Mistake {
        /// Which.
        mistake: Mistake,
        /// Albedo.
        albedo: DVec3,
        /// Index of refraction (the dielectric's).
        ior: f64,
    },
}

/// The course's BRDFs (week 8's `RT_material`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CourseBrdf {
    /// `Lambertian.BRDF`: the albedo (no `1 / pi`).
    Lambertian {
        /// Albedo.
        albedo: DVec3,
    },
    /// `Phong.BRDF`.
    Phong {
        /// Albedo.
        albedo: DVec3,
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Exponent.
        alpha: f64,
    },
    /// `Blinn.BRDF`.
    Blinn {
        /// Albedo.
        albedo: DVec3,
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Exponent.
        alpha: f64,
    },
    /// `CookTorrance.BRDF` (grey).
    CookTorrance {
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// GGX roughness.
        alpha: f64,
        /// Index of refraction of Schlick's Fresnel.
        ior: f64,
    },
}

impl CourseBrdf {
    /// `BRDF(ray_view, ray_light, hit)` with the view ray's direction `-wo` and the light ray's
    /// `light` (the course's own, possibly unnormalised, direction).
    fn eval(&self, wo: DVec3, light: DVec3, n: DVec3) -> DVec3 {
        let view = -wo;
        match *self {
            CourseBrdf::Lambertian { albedo } => albedo,
            CourseBrdf::Phong {
                albedo,
                kd,
                ks,
                alpha,
            } => brdf::phong(albedo, kd, ks, alpha, view, light, n),
            CourseBrdf::Blinn {
                albedo,
                kd,
                ks,
                alpha,
            } => brdf::blinn(albedo, kd, ks, alpha, view, light, n),
            CourseBrdf::CookTorrance { kd, ks, alpha, ior } => {
                brdf::cook_torrance(kd, ks, alpha, ior, view, light, n)
            }
        }
    }
}

fn v3(value: &serde_json::Value, key: &str) -> Result<DVec3, String> {
    let a = value
        .get(key)
        .and_then(|v| v.as_array())
        .ok_or_else(|| format!("the material has no \"{key}\" (three numbers)"))?;
    let n: Vec<f64> = a.iter().filter_map(serde_json::Value::as_f64).collect();
    if n.len() != 3 || a.len() != 3 || n.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "the material's \"{key}\" is not three finite numbers"
        ));
    }
    Ok(DVec3::new(n[0], n[1], n[2]))
}

fn num(value: &serde_json::Value, key: &str) -> Result<f64, String> {
    value
        .get(key)
        .and_then(serde_json::Value::as_f64)
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("the material has no \"{key}\" (a finite number)"))
}

impl Model {
    /// The model of the protocol's material description `value` in `family`; `Err` says why
    /// there is none (a type the family does not have, a missing parameter).
    pub fn from_json(value: &serde_json::Value, family: Family) -> Result<Model, String> {
        let kind = value
            .get("type")
            .and_then(serde_json::Value::as_str)
            .ok_or("the material has no \"type\"")?;
        let albedo = || v3(value, "albedo");
        match (family, kind) {
            (Family::Book, "lambertian") => Ok(Model::Lambertian { albedo: albedo()? }),
            (Family::Book, "metal") => Ok(Model::Metal {
                albedo: albedo()?,
                fuzz: num(value, "roughness")?.clamp(0.0, 1.0),
            }),
            (Family::Book, "dielectric") => Ok(Model::Dielectric {
                albedo: v3(value, "albedo").unwrap_or(DVec3::ONE),
                ior: num(value, "ior")?,
            }),
            (Family::Book, "mirror") => Ok(Model::Mirror { albedo: albedo()? }),
            (Family::Course { cosine }, _) => {
                let brdf = match kind {
                    "lambertian" => CourseBrdf::Lambertian { albedo: albedo()? },
                    "phong" | "blinn" => {
                        let (albedo, kd, ks, alpha) = (
                            albedo()?,
                            num(value, "kd")?,
                            num(value, "ks")?,
                            num(value, "alpha")?,
                        );
                        if kind == "phong" {
                            CourseBrdf::Phong {
                                albedo,
                                kd,
                                ks,
                                alpha,
                            }
                        } else {
                            CourseBrdf::Blinn {
                                albedo,
                                kd,
                                ks,
                                alpha,
                            }
                        }
                    }
                    "cook_torrance" => CourseBrdf::CookTorrance {
                        kd: num(value, "kd")?,
                        ks: num(value, "ks")?,
                        alpha: num(value, "alpha")?,
                        ior: num(value, "ior")?,
                    },
                    other => {
                        return Err(format!(
                            "the course's materials checked here are lambertian, phong, blinn \
                             and cook_torrance, not {other:?}"
                        ));
                    }
                };
                Ok(Model::Course { brdf, cosine })
            }
            (Family::Book, other) => Err(format!(
                "the book's materials are lambertian, metal, dielectric and mirror, not {other:?}"
            )),
        }
    }

    /// The sample drawn with the numbers `u` (four uniform numbers in `[0, 1)`), for the
    /// outgoing direction `wo` at a surface of unit normal `n`; `None` when absorbed.
    pub fn sample(&self, wo: DVec3, n: DVec3, u: [f64; 4]) -> Option<MaterialSample> {
        match *self {
            Model::Lambertian { albedo } => {
                let wi = lambertian_direction(n, u);
                Some(continuous(wi, albedo, wi.dot(n).max(0.0) / PI))
            }
            Model::Metal { albedo, fuzz } => {
                let r = reflect(-wo, n);
                if fuzz == 0.0 {
                    return (r.dot(n) > 0.0).then(|| delta(r, albedo, 1.0));
                }
                let d = (r + fuzz * sphere_point(u[0], u[1])).normalize();
                (d.dot(n) > 0.0).then(|| continuous(d, albedo, fuzz_pdf(r, d, fuzz)))
            }
            Model::Dielectric { albedo, ior } => Some(dielectric(wo, n, ior, u[0], albedo, true)),
            Model::Mirror { albedo } => Some(delta(reflect(-wo, n), albedo, 1.0)),
            Model::Course { brdf, cosine } => {
                let raw = if cosine {
                    let (r1, r2) = (u[0], u[1]);
                    let phi = 2.0 * PI * r1;
                    let s = r2.sqrt();
                    let local =
                        DVec3::new(libm::cos(phi) * s, libm::sin(phi) * s, (1.0 - r2).sqrt());
                    Onb::from_w(n).local(local)
                } else {
                    n + sphere_point(u[0], u[1])
                };
                let c = n.dot(raw);
                let cut = if c < 1e-6 { 0.0 } else { c };
                let weight = brdf.eval(wo, raw, n) * cut;
                Some(MaterialSample {
                    wi: raw.normalize(),
                    weight,
                    pdf: None,
                    delta: false,
                })
            }
            Model::Mistake {
                mistake,
                albedo,
                ior,
            } => mistake_sample(mistake, albedo, ior, wo, n, u),
        }
    }

    /// The BSDF `f(wo, wi)` (zero for a delta material).
    pub fn eval(&self, wo: DVec3, n: DVec3, wi: DVec3) -> DVec3 {
        let above = wi.dot(n) > 0.0;
        match *self {
            Model::Lambertian { albedo } if above => albedo / PI,
            Model::Metal { albedo, fuzz } if above && fuzz > 0.0 => {
                albedo * fuzz_pdf(reflect(-wo, n), wi, fuzz) / wi.dot(n)
            }
            Model::Course { brdf, .. } => {
                if wi.dot(n) < 1e-6 {
                    DVec3::ZERO
                } else {
                    brdf.eval(wo, wi, n)
                }
            }
            Model::Mistake {
                mistake, albedo, ..
            } if above => match mistake {
                Mistake::NoTotalInternalReflection => DVec3::ZERO,
                Mistake::EnergyGain => albedo,
                Mistake::NonReciprocal => albedo * (1.0 - schlick(wi.dot(n), 1.5)) / PI,
                _ => albedo / PI,
            },
            _ => DVec3::ZERO,
        }
    }

    /// The pdf of the directions [`Model::sample`] returns, per unit solid angle (`None`: the
    /// model has none, as the course's materials).
    pub fn pdf(&self, wo: DVec3, n: DVec3, wi: DVec3) -> Option<f64> {
        let c = wi.dot(n);
        Some(match *self {
            Model::Lambertian { .. } => c.max(0.0) / PI,
            Model::Metal { fuzz, .. } if fuzz > 0.0 && c > 0.0 => {
                fuzz_pdf(reflect(-wo, n), wi, fuzz)
            }
            Model::Course { .. } => return None,
            Model::Mistake { mistake, .. } => match mistake {
                Mistake::NoTotalInternalReflection => 0.0,
                Mistake::PdfMissingCosine if c > 0.0 => 1.0 / PI,
                _ => c.max(0.0) / PI,
            },
            _ => 0.0,
        })
    }
}

/// A sample of a continuous lobe.
fn continuous(wi: DVec3, weight: DVec3, pdf: f64) -> MaterialSample {
    MaterialSample {
        wi,
        weight,
        pdf: Some(pdf),
        delta: false,
    }
}

/// A sample of a delta lobe chosen with probability `p`.
fn delta(wi: DVec3, weight: DVec3, p: f64) -> MaterialSample {
    MaterialSample {
        wi,
        weight,
        pdf: Some(p),
        delta: true,
    }
}

/// The point of the unit sphere of `(u0, u1)`: `z = 1 - 2 u0`, `phi = 2 pi u1` (uniform).
pub fn sphere_point(u0: f64, u1: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u1;
    DVec3::new(r * libm::cos(phi), r * libm::sin(phi), z)
}

/// The book's Lambertian direction: `unit(n + random_unit_vector())`, `n` where the sum
/// vanishes.
fn lambertian_direction(n: DVec3, u: [f64; 4]) -> DVec3 {
    let d = n + sphere_point(u[0], u[1]);
    if d.length_squared() < 1e-16 {
        n
    } else {
        d.normalize()
    }
}

/// The density of `unit(r + f s)` for `s` uniform on the unit sphere, `r` a unit vector and
/// `0 < f <= 1`, at the unit direction `d` making the angle `a` with `r`: the two points where
/// the ray along `d` meets the sphere of radius `f` about `r` both map to `d`, at
/// `t = cos a +- sqrt(f^2 - sin^2 a)`, each with density `1 / (4 pi f^2)` times
/// `t^2 / |cos|` (`|cos| = sqrt(f^2 - sin^2 a) / f`), which sums to
/// `(cos 2a + f^2) / (2 pi f sqrt(f^2 - sin^2 a))` where `sin a < f` (and `cos a > 0`), else 0.
/// At `f = 1` the near root is `t = 0` and the density is `cos a / pi`.
pub fn fuzz_pdf(r: DVec3, d: DVec3, f: f64) -> f64 {
    let c = r.dot(d).clamp(-1.0, 1.0);
    let s2 = 1.0 - c * c;
    let g = f * f - s2;
    if c <= 0.0 || g <= 0.0 {
        return 0.0;
    }
    let sq = g.sqrt();
    let (t_far, t_near) = (c + sq, (c - sq).max(0.0));
    (t_far * t_far + t_near * t_near) / (4.0 * PI * f * sq)
}

/// The book's dielectric (with `tir`; without it, the mistake that refracts anyway): from `wo`
/// (outside when on the normal's side), reflect under total internal reflection or when
/// Schlick's reflectance is above `u`, else refract.
fn dielectric(wo: DVec3, n: DVec3, ior: f64, u: f64, albedo: DVec3, tir: bool) -> MaterialSample {
    let outside = wo.dot(n) > 0.0;
    let (facing, ratio) = if outside { (n, 1.0 / ior) } else { (-n, ior) };
    let v = -wo;
    let cos = (-v.dot(facing)).min(1.0);
    let sin = (1.0 - cos * cos).sqrt();
    let cannot = ratio * sin > 1.0;
    let r = schlick(cos, ratio);
    if tir && cannot {
        return delta(reflect(v, facing), albedo, 1.0);
    }
    if r > u {
        return delta(reflect(v, facing), albedo, r);
    }
    let perp = ratio * (v + cos * facing);
    let par = -(1.0 - perp.length_squared()).abs().sqrt() * facing;
    delta(perp + par, albedo, 1.0 - r)
}

fn mistake_sample(
    mistake: Mistake,
    albedo: DVec3,
    ior: f64,
    wo: DVec3,
    n: DVec3,
    u: [f64; 4],
) -> Option<MaterialSample> {
    let wi = lambertian_direction(n, u);
    let c = wi.dot(n).max(0.0);
    Some(match mistake {
        Mistake::PdfMissingCosine => {
            // f cos / pdf with the pdf missing its cosine.
            continuous(wi, albedo / PI * c * PI, 1.0 / PI)
        }
        Mistake::UniformWithCosinePdf => {
            let s = sphere_point(u[0], u[1]);
            let wi = if s.dot(n) < 0.0 { -s } else { s };
            continuous(wi, albedo, wi.dot(n) / PI)
        }
        Mistake::WeightNotDivided => continuous(wi, albedo / PI * c, c / PI),
        Mistake::NoTotalInternalReflection => dielectric(wo, n, ior, u[0], albedo, false),
        Mistake::EnergyGain => continuous(wi, albedo * PI, c / PI),
        Mistake::NonReciprocal => continuous(wi, albedo * (1.0 - schlick(c, 1.5)), c / PI),
    })
}

/// rtoracle's models as a [`MaterialSource`], with no process and no JSON: the checks' honest
/// subjects and, with a mistake, their catalogued failures.
pub struct ModelSource {
    family: Family,
    /// A mistake standing for its material type.
    pub mistake: Option<Mistake>,
}

impl ModelSource {
    /// The models of `family`.
    pub fn new(family: Family) -> Self {
        ModelSource {
            family,
            mistake: None,
        }
    }

    /// The book's models with `mistake` in place of its material type.
    pub fn with_mistake(mistake: Mistake) -> Self {
        ModelSource {
            family: Family::Book,
            mistake: Some(mistake),
        }
    }

    /// The model answering for `material`.
    pub fn model(&self, material: &serde_json::Value) -> Result<Model, Problem> {
        if let Some(m) = self.mistake {
            let kind = material.get("type").and_then(serde_json::Value::as_str);
            if kind == Some(m.material_type()) {
                return Ok(Model::Mistake {
                    mistake: m,
                    albedo: v3(material, "albedo").unwrap_or(DVec3::ONE),
                    ior: num(material, "ior").unwrap_or(1.5),
                });
            }
        }
        Model::from_json(material, self.family).map_err(Problem::Declined)
    }
}

impl MaterialSource for ModelSource {
    fn label(&self) -> String {
        match (self.family, self.mistake) {
            (_, Some(m)) => format!("rtoracle model with the mistake {}", m.name()),
            (Family::Book, None) => "rtoracle's models of the book's materials".into(),
            (Family::Course { .. }, None) => "rtoracle's models of the course's materials".into(),
        }
    }

    fn supports(&self, op: Op) -> bool {
        op != Op::Pdf || self.family == Family::Book
    }

    fn sample(
        &mut self,
        material: &serde_json::Value,
        wo: DVec3,
        n: DVec3,
        u: &[[f64; 4]],
    ) -> Result<Vec<Option<MaterialSample>>, Problem> {
        let model = self.model(material)?;
        Ok(u.iter().map(|&u| model.sample(wo, n, u)).collect())
    }

    fn eval(
        &mut self,
        material: &serde_json::Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<DVec3>, Problem> {
        let model = self.model(material)?;
        Ok(wi.iter().map(|&w| model.eval(wo, n, w)).collect())
    }

    fn pdf(
        &mut self,
        material: &serde_json::Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<f64>, Problem> {
        let model = self.model(material)?;
        wi.iter()
            .map(|&w| {
                model
                    .pdf(wo, n, w)
                    .ok_or_else(|| Problem::Declined("the model has no pdf".into()))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fuzz density integrates to 1 over the directions above the reflection's cone
    /// (midpoint rule in the angle from `r`, fine near the singular edge), and at `f = 1` it
    /// is the cosine lobe about `r`.
    #[test]
    fn fuzz_pdf_is_a_density() {
        let r = DVec3::Z;
        for f in [0.1, 0.3, 0.7, 1.0] {
            let steps = 2_000_000;
            let amax = f64::asin(f).min(PI / 2.0);
            let h = amax / steps as f64;
            let mut total = 0.0;
            for k in 0..steps {
                let a = (k as f64 + 0.5) * h;
                let d = DVec3::new(a.sin(), 0.0, a.cos());
                total += fuzz_pdf(r, d, f) * 2.0 * PI * a.sin() * h;
            }
            assert!((total - 1.0).abs() < 2e-3, "f {f}: {total}");
        }
        let d = DVec3::new(0.6, 0.0, 0.8);
        assert!((fuzz_pdf(r, d, 1.0) - 0.8 / PI).abs() < 1e-12);
    }

    /// The book's Lambertian keeps the albedo as weight and reports `cos / pi`; its weight is
    /// `f cos / pdf` exactly.
    #[test]
    fn lambertian_weight_is_f_cos_over_pdf() {
        let n = DVec3::new(0.0, 0.6, 0.8);
        let m = Model::Lambertian {
            albedo: DVec3::new(0.8, 0.5, 0.2),
        };
        let s = m.sample(n, n, [0.3, 0.7, 0.0, 0.0]).unwrap();
        let c = s.wi.dot(n);
        let expected = m.eval(n, n, s.wi) * c / s.pdf.unwrap();
        assert!((s.weight - expected).abs().max_element() < 1e-12);
    }
}
