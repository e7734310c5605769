//! The seeds a candidate sees, derived from a rubric's secret seed.
//!
//! A rubric's `seed` is a secret: with it, the week-4 vectors, the function checks' inputs and
//! which rows of a render are checked can all be known in advance (`rtoracle vectors --seed S`
//! prints the suite). So it never leaves the grader: every seed that goes into a request (a
//! render's, a sampler's, a steered scattering's) and every generator whose output a request
//! shows (the vector suite, a check's random inputs) is `derive`d from the secret and the
//! purpose it serves, by a keyed one-way function: HMAC-SHA256 (RFC 2104) keyed with the
//! secret, over the purpose's name. Knowing one derived seed (a render request's, printed by a
//! hostile submission) gives neither the secret nor any other purpose's seed: that would take
//! inverting SHA-256, or guessing the secret's 64 bits one HMAC at a time.
//!
//! HMAC-SHA256 comes from the RustCrypto `hmac` crate over the `sha2` the crate already uses for
//! its hashes: a well-kept, audited pair, pure Rust, and a construction made for exactly this
//! (a pseudo-random function keyed by a secret); a home-made mix of the seed (an FNV or a
//! PCG step, which the generators use) is invertible from its output.
//!
//! [`digest`] names a secret without revealing it (for `report.json` and shard checks: two
//! grades made with the same secret have the same digest).

use hmac::{Hmac, KeyInit, Mac};
use sha2::Sha256;

/// The domain of every derivation, so that no other use of HMAC-SHA256 under the same key can
/// collide with these.
const DOMAIN: &[u8] = b"rtoracle seed derivation v1\0";

/// HMAC-SHA256 of `DOMAIN || message` keyed with the secret's eight bytes (little-endian).
fn mac(secret: u64, message: &[u8]) -> [u8; 32] {
    let mut m = <Hmac<Sha256> as KeyInit>::new_from_slice(&secret.to_le_bytes())
        .expect("HMAC takes a key of any length");
    m.update(DOMAIN);
    m.update(message);
    m.finalize().into_bytes().into()
}

/// The seed for `purpose` (`"vectors"`, `"render/week05-quad"`, ...) under the secret `secret`:
/// the first eight bytes of HMAC-SHA256, little-endian.
pub fn derive(secret: u64, purpose: &str) -> u64 {
    let bytes = mac(secret, purpose.as_bytes());
    u64::from_le_bytes(bytes[..8].try_into().expect("8 bytes"))
}

/// `derive`, kept to 32 bits (a seed that Python's and numpy's generators take as it is).
pub fn derive32(secret: u64, purpose: &str) -> u32 {
    (derive(secret, purpose) & 0xFFFF_FFFF) as u32
}

/// A name for the secret that does not reveal it: `hmac-sha256:` and 16 hex digits of the
/// derivation for the purpose `"digest"`.
pub fn digest(secret: u64) -> String {
    format!("hmac-sha256:{:016x}", derive(secret, "digest"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// HMAC-SHA256 itself, against RFC 4231's test case 2 (key "Jefe"), computed here through
    /// the same crate calls: the derivation is the standard construction.
    #[test]
    fn hmac_sha256_is_rfc_4231s() {
        let mut m = <Hmac<Sha256> as KeyInit>::new_from_slice(b"Jefe").unwrap();
        m.update(b"what do ya want for nothing?");
        let out: [u8; 32] = m.finalize().into_bytes().into();
        let hex: String = out.iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(
            hex,
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
        );
    }

    #[test]
    fn purposes_and_secrets_give_unrelated_seeds() {
        let a = derive(987_654_321, "vectors");
        assert_ne!(a, derive(987_654_321, "functions"));
        assert_ne!(a, derive(987_654_322, "vectors"));
        assert_ne!(a, 987_654_321);
        // Deterministic.
        assert_eq!(a, derive(987_654_321, "vectors"));
        // The digest says nothing a seed would.
        let d = digest(987_654_321);
        assert!(d.starts_with("hmac-sha256:") && d.len() == 12 + 16, "{d}");
        assert!(!d.contains("987654321") && !d.contains("3ade68b1"), "{d}");
    }

    #[test]
    fn the_low_bits_of_derived_seeds_are_balanced() {
        // 4096 purposes: each of the low 32 bits is set about half the time (a binomial count
        // of 4096 at p = 1/2 outside 1748..2348 has probability under 1e-20 per bit).
        let mut ones = [0u32; 32];
        for k in 0..4096 {
            let s = derive32(7, &format!("p/{k}"));
            for (b, n) in ones.iter_mut().enumerate() {
                *n += (s >> b) & 1;
            }
        }
        assert!(ones.iter().all(|&n| (1748..=2348).contains(&n)), "{ones:?}");
    }
}
