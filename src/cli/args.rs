//! Options several subcommands share: `--profile` and `--precision` ([`JudgingArgs`]), and the
//! numeric options, parsed the same way everywhere.
//!
//! Each numeric option takes a value parser from here, so that `--seed -1`, `--seed=-1`,
//! `--spp -2`, `--width 1e308`, `--count NaN` and `--threads 99999999999` all get the same kind
//! of answer: one line naming the option, the value and the range it must be in (clap puts the
//! option's name in front of the message), exit 2, before any work. Negative numbers are accepted
//! as values by the parser (see [`allow_negative_numbers`]) so that they reach these checks
//! instead of clap's "unexpected argument" with its misleading `-- -1` tip.

use rtoracle::oracle::profile::{Judging, Precision, Profile};

/// An integer in `LO..=HI`.
pub fn int_in<const LO: u64, const HI: u64>(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let what = || {
        if HI == u64::MAX {
            format!("must be an integer of at least {LO}")
        } else {
            format!("must be an integer from {LO} to {HI}")
        }
    };
    if t.starts_with('-') && t.len() > 1 && t[1..].bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("{}, not a negative number", what()));
    }
    if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
        return Err(what());
    }
    match t.parse::<u64>() {
        Ok(n) if (LO..=HI).contains(&n) => Ok(n),
        _ => Err(what()),
    }
}

/// A seed: any integer from 0 to 2^64 - 1.
pub fn seed(s: &str) -> Result<u64, String> {
    int_in::<0, { u64::MAX }>(s).map_err(|_| "must be an integer from 0 to 2^64-1".to_string())
}

/// Samples per pixel: 1 to 1,000,000.
pub fn spp(s: &str) -> Result<u32, String> {
    int_in::<1, 1_000_000>(s).map(|n| n as u32)
}

/// Worker threads: 1 to 1024.
pub fn threads(s: &str) -> Result<usize, String> {
    int_in::<1, 1024>(s).map(|n| n as usize)
}

/// An image width in pixels: 1 to 100,000.
pub fn width(s: &str) -> Result<usize, String> {
    int_in::<1, 100_000>(s).map(|n| n as usize)
}

/// A number of vectors or cases: 1 to 10,000,000 (a vector takes about 300 bytes in memory).
pub fn count(s: &str) -> Result<usize, String> {
    int_in::<1, 10_000_000>(s).map(|n| n as usize)
}

/// Failures to show: 0 to 1,000,000.
pub fn show(s: &str) -> Result<usize, String> {
    int_in::<0, 1_000_000>(s).map(|n| n as usize)
}

/// Benchmark runs: 1 to 1000.
pub fn runs(s: &str) -> Result<u32, String> {
    int_in::<1, 1000>(s).map(|n| n as u32)
}

/// The width of `bench render`'s memory render, a square: 1 to 10,000 (`render` makes at most
/// 100 million pixels).
pub fn memory_width(s: &str) -> Result<u32, String> {
    int_in::<1, 10_000>(s)
        .map(|n| n as u32)
        .map_err(|e| format!("{e} (the square render makes at most 100 million pixels)"))
}

/// A time limit in milliseconds: 1 ms to one hour.
pub fn millis(s: &str) -> Result<u64, String> {
    int_in::<1, 3_600_000>(s)
}

/// A course week: 4 (intersections only) to 10.
pub fn week(s: &str) -> Result<u8, String> {
    int_in::<4, 10>(s).map(|n| n as u8)
}

/// A false-alarm rate: a probability from 1e-12 to 0.5.
pub fn alpha(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && (1e-12..=0.5).contains(&x) => Ok(x),
        _ => Err("must be a probability from 1e-12 to 0.5".to_string()),
    }
}

/// A number of seconds: finite, from 0.001 to one week.
pub fn seconds(s: &str) -> Result<f64, String> {
    const WEEK: f64 = 7.0 * 24.0 * 3600.0;
    let what = || format!("must be a number of seconds from 0.001 to {WEEK}");
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && (0.001..=WEEK).contains(&x) => Ok(x),
        _ => Err(what()),
    }
}

/// Sets `allow_negative_numbers` on every command, so a negative value reaches the value
/// parsers above instead of being taken for an unknown flag.
pub fn allow_negative_numbers(cmd: clap::Command) -> clap::Command {
    cmd.allow_negative_numbers(true)
        .mut_subcommands(allow_negative_numbers)
}

/// `--profile` and `--precision` (shared by `check`, `fuzz`, `vectors` and `explain`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct JudgingArgs {
    /// Whose formulas draw the line between definite and ambiguous: `course` (the course's
    /// naive formulas; the default) or `robust` (the reference's robust formulas: finds the
    /// precision bugs of naive code).
    #[arg(long, value_name = "course|robust")]
    pub profile: Option<Profile>,
    /// The precision the candidate computes in: `f64` (the default) or `f32` (inputs rounded to
    /// f32, bands and tolerances of f32 arithmetic).
    #[arg(long, value_name = "f64|f32")]
    pub precision: Option<Precision>,
}

impl JudgingArgs {
    /// The judging, with `default` for an absent `--profile`.
    pub fn judging(&self, default: Profile) -> Judging {
        Judging::new(
            self.profile.unwrap_or(default),
            self.precision.unwrap_or_default(),
        )
    }

    /// Whether either flag was given.
    pub fn given(&self) -> bool {
        self.profile.is_some() || self.precision.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_inclusive_and_everything_else_is_refused() {
        assert_eq!(int_in::<1, 10>("1"), Ok(1));
        assert_eq!(int_in::<1, 10>("10"), Ok(10));
        for bad in [
            "0",
            "11",
            "-1",
            "1e3",
            "NaN",
            "inf",
            "",
            " ",
            "+3",
            "1.0",
            "99999999999999999999999",
        ] {
            assert!(int_in::<1, 10>(bad).is_err(), "{bad:?}");
        }
        assert!(int_in::<1, 10>("-1").unwrap_err().contains("negative"));
        assert_eq!(seed("18446744073709551615"), Ok(u64::MAX));
        assert!(seed("18446744073709551616").is_err());
        assert!(seed("-1").is_err());
        assert_eq!(seconds("0.5"), Ok(0.5));
        for bad in ["0", "1e-300", "1e308", "NaN", "inf", "-1"] {
            assert!(seconds(bad).is_err(), "{bad:?}");
        }
    }
}
