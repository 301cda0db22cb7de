//! The blob fuzz targets' (`tables`, `family`) second reading of an input: a mutation of one of
//! the target's seed blobs, resealed with a valid checksum so that the reader's checks past the
//! checksum are reached; and what a blob the reader accepts must do (shared with
//! `crates/gonio/tests/tables.rs`).

use gonio::mapping::blob::{self, MapTables};
use gonio::{Point2, Sampler, Vec3};
use std::sync::OnceLock;

/// The seed picked by the input's first byte with sparse (position, xor) mutations from the
/// rest, its checksum recomputed; and the bytes after the first (the target's own extra input).
/// The seeds are made by `make` on the first call and kept (one set per fuzz target process).
pub fn mutated(make: fn() -> Vec<Vec<u8>>, data: &[u8]) -> Option<(Vec<u8>, &[u8])> {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    let seeds = SEEDS.get_or_init(make);
    let (&pick, rest) = data.split_first()?;
    let mut b = seeds[pick as usize % seeds.len()].clone();
    for c in rest.chunks_exact(3) {
        let at = (u16::from_le_bytes([c[0], c[1]]) as usize) % b.len();
        b[at] ^= c[2];
    }
    reseal(&mut b);
    Some((b, rest))
}

/// Recomputes the checksum of a modified blob.
pub fn reseal(b: &mut [u8]) {
    let c = blob::checksum(b);
    b[blob::CHECKSUM_OFFSET..blob::CHECKSUM_OFFSET + 8].copy_from_slice(&c.to_le_bytes());
}

/// An accepted blob samples the point `u` of the square to a unit direction with a finite
/// density ≥ 0, evaluates it alike, and inverts it into the square (or refuses with an error).
pub fn assert_sane_sample(t: &MapTables, u: Point2) {
    let s = t.sample(u);
    assert!(s.pdf.is_finite() && s.pdf >= 0.0, "pdf {s:?} at {u:?}");
    let n = s.direction.iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!((n - 1.0).abs() < 1e-3, "direction {s:?} at {u:?}");
    assert_sane_direction(t, s.direction);
}

/// An accepted blob evaluates any direction `d` (unit, zero or not finite) to a finite density
/// ≥ 0 and inverts it into the square or refuses with an error.
pub fn assert_sane_direction(t: &MapTables, d: Vec3) {
    let p = t.pdf(d);
    assert!(p.is_finite() && p >= 0.0, "pdf {p} at {d:?}");
    if let Ok(b) = t.invert(d) {
        assert!(
            b.iter().all(|x| (0.0..=1.0).contains(x)),
            "invert {b:?} at {d:?}"
        );
    }
}
