//! How 8-bit codes map back to intervals of linear values.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// An encoding of linear values into 8-bit codes.
///
/// Decoding a code gives the interval of linear values that the encoding maps to it; encodings
/// that some students round and others truncate (sRGB, gamma 2.2, linear) decode to the hull of
/// both intervals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// The course's: `floor(255 * clamp(sqrt(x), 0, 0.999))`, so 254 is the largest code.
    Course,
    /// *Ray Tracing in One Weekend*'s: `floor(256 * clamp(sqrt(x), 0, 0.999))`.
    Rtiow,
    /// The sRGB transfer curve, rounded or truncated.
    Srgb,
    /// `x^(1/2.2)`, rounded or truncated.
    Gamma22,
    /// No transfer curve: `255 x`, rounded or truncated.
    Linear,
    /// The course's gamma applied twice: `floor(255 * clamp(sqrt(sqrt(x)), 0, 0.999))` (a
    /// mistake the diagnosis tests, not an encoding an assignment asks for).
    GammaTwice,
}

/// Every encoding, in the order the diagnosis tries them.
pub const ENCODINGS: [Encoding; 6] = [
    Encoding::Course,
    Encoding::Rtiow,
    Encoding::Srgb,
    Encoding::Gamma22,
    Encoding::Linear,
    Encoding::GammaTwice,
];

/// Marks a code the encoding can never produce: its "interval" lies far outside `[0, 1]`.
const IMPOSSIBLE: (f64, f64) = (2.0, 2.0);

fn srgb_to_linear(g: f64) -> f64 {
    if g <= 0.04045 {
        g / 12.92
    } else {
        ((g + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

impl Encoding {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Course => "course",
            Encoding::Rtiow => "rtiow",
            Encoding::Srgb => "srgb",
            Encoding::Gamma22 => "gamma22",
            Encoding::Linear => "linear",
            Encoding::GammaTwice => "gamma-twice",
        }
    }

    /// The transfer curve from linear to encoded `[0, 1]` values (before scaling to codes).
    fn curve(self, x: f64) -> f64 {
        let x = if x > 0.0 { x } else { 0.0 };
        match self {
            Encoding::Course | Encoding::Rtiow => x.sqrt(),
            Encoding::Srgb => linear_to_srgb(x.min(1.0)),
            Encoding::Gamma22 => x.min(1.0).powf(1.0 / 2.2),
            Encoding::Linear => x,
            Encoding::GammaTwice => x.sqrt().sqrt(),
        }
    }

    /// The inverse of [`Encoding::curve`].
    fn inverse(self, g: f64) -> f64 {
        let g = g.clamp(0.0, 1.0);
        match self {
            Encoding::Course | Encoding::Rtiow => g * g,
            Encoding::Srgb => srgb_to_linear(g),
            Encoding::Gamma22 => g.powf(2.2),
            Encoding::Linear => g,
            Encoding::GammaTwice => (g * g) * (g * g),
        }
    }

    /// The code this encoding gives the linear value `x` (rounded for the curves that are
    /// usually rounded).
    pub fn encode(self, x: f64) -> u8 {
        let g = self.curve(x);
        match self {
            Encoding::Course | Encoding::GammaTwice => (255.0 * g.clamp(0.0, 0.999)) as u8,
            Encoding::Rtiow => (256.0 * g.clamp(0.0, 0.999)) as u8,
            _ => (255.0 * g.clamp(0.0, 1.0)).round() as u8,
        }
    }

    /// The interval `[lo, hi]` of linear values in `[0, 1]` that may be written as `code`.
    /// Codes the encoding cannot produce (255 under the course's) decode far outside `[0, 1]`.
    /// The bounds are widened by a relative 1e-12 so that float rounding in the encoder (for
    /// instance `sqrt(0.04) * 255 = 51` exactly while `(51 / 255)^2 > 0.04`) stays inside.
    pub fn decode(self, code: u8) -> (f64, f64) {
        let (lo, hi) = self.decode_exact(code);
        if lo > 1.0 {
            return (lo, hi);
        }
        (lo * (1.0 - 1e-12), hi * (1.0 + 1e-12))
    }

    fn decode_exact(self, code: u8) -> (f64, f64) {
        let q = code as f64;
        match self {
            Encoding::Course | Encoding::GammaTwice => match code {
                255 => IMPOSSIBLE,
                254 => (self.inverse(254.0 / 255.0), 1.0),
                _ => (self.inverse(q / 255.0), self.inverse((q + 1.0) / 255.0)),
            },
            Encoding::Rtiow => match code {
                255 => (self.inverse(255.0 / 256.0), 1.0),
                _ => (self.inverse(q / 256.0), self.inverse((q + 1.0) / 256.0)),
            },
            _ => {
                // Hull of the rounded interval [q - 0.5, q + 0.5) and the truncated [q, q + 1).
                let lo = ((q - 0.5) / 255.0).max(0.0);
                let hi = ((q + 1.0) / 255.0).min(1.0);
                let hi = if code == 255 { 1.0 } else { hi };
                (self.inverse(lo), self.inverse(hi))
            }
        }
    }

    /// A table of [`Encoding::decode`] for all 256 codes.
    pub fn table(self) -> [(f64, f64); 256] {
        let mut t = [(0.0, 0.0); 256];
        for (code, entry) in t.iter_mut().enumerate() {
            *entry = self.decode(code as u8);
        }
        t
    }
}

impl FromStr for Encoding {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ENCODINGS
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| {
                format!("unknown encoding '{s}' (expected course, rtiow, srgb, gamma22, linear or gamma-twice)")
            })
    }
}

impl std::fmt::Display for Encoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::encode_course_png;

    #[test]
    fn every_encoded_value_lies_in_its_decoded_interval() {
        // A dense sweep of [0, 1]: encoding then decoding must bracket the value, for every
        // encoding (the decoder is the inverse of the encoder, interval-wise).
        for e in ENCODINGS {
            for k in 0..=20_000 {
                let x = k as f64 / 20_000.0;
                let (lo, hi) = e.decode(e.encode(x));
                assert!(lo <= x && x <= hi, "{e}: {x} -> [{lo}, {hi}]");
            }
        }
    }

    #[test]
    fn course_decoding_matches_the_course_encoder() {
        for k in 0..=50_000 {
            let x = k as f64 / 50_000.0;
            let q = encode_course_png(x);
            assert_eq!(q, Encoding::Course.encode(x));
            let (lo, hi) = Encoding::Course.decode(q);
            assert!(lo <= x && x <= hi);
        }
        // Closed forms: code 127 covers sqrt(x) in [127/255, 128/255).
        let (lo, hi) = Encoding::Course.decode(127);
        assert!((lo / (127.0f64 / 255.0).powi(2) - 1.0).abs() < 1e-11);
        assert!((hi / (128.0f64 / 255.0).powi(2) - 1.0).abs() < 1e-11);
        // 255 cannot come out of the course's encoder.
        assert!(Encoding::Course.decode(255).0 > 1.0);
    }

    #[test]
    fn names_round_trip() {
        for e in ENCODINGS {
            assert_eq!(e.name().parse::<Encoding>().unwrap(), e);
        }
        assert!("sqrt".parse::<Encoding>().is_err());
    }
}
