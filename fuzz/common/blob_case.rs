//! The blob fuzz targets' (`tables`, `family`) second reading of an input: a mutation of one of
//! the target's seed blobs, resealed with a valid checksum so that the reader's checks past the
//! checksum are reached.

use gonio::mapping::blob;
use std::sync::OnceLock;

/// The seed picked by the input's first byte with sparse (position, xor) mutations from the
/// rest, its checksum recomputed; and the bytes after the first (the target's own extra input).
/// The seeds are made by `make` on the first call and kept (one set per fuzz target process).
pub fn mutated<'a>(make: fn() -> Vec<Vec<u8>>, data: &'a [u8]) -> Option<(Vec<u8>, &'a [u8])> {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    let seeds = SEEDS.get_or_init(make);
    let (&pick, rest) = data.split_first()?;
    let mut b = seeds[pick as usize % seeds.len()].clone();
    for c in rest.chunks_exact(3) {
        let at = (u16::from_le_bytes([c[0], c[1]]) as usize) % b.len();
        b[at] ^= c[2];
    }
    let c = blob::checksum(&b);
    b[blob::CHECKSUM_OFFSET..blob::CHECKSUM_OFFSET + 8].copy_from_slice(&c.to_le_bytes());
    Some((b, rest))
}
