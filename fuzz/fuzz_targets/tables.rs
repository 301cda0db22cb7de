//! Fuzz target: the table blob reader (docs/TABLES.md) must never panic or read out of bounds;
//! a blob it accepts must sample, evaluate and invert without panicking, with finite unit
//! directions and finite densities ≥ 0 from finite points, and must write back (an f32 blob) to
//! the same bytes. The first input byte picks a seed blob to mutate when the input is short, so
//! that the fuzzer reaches the content checks past the checksum: the rest of the input is
//! XOR-ed into a valid blob, which is then resealed (its checksum recomputed).
#![no_main]

use gonio::mapping::blob::{self, Frame, Precision, ReadMap, Target};
use gonio::{Diagram, HemisphereMap, MapRef, Sampler, SphereLayout, SphereMap};
use libfuzzer_sys::fuzz_target;

#[path = "../common/blob_case.rs"]
mod blob_case;

/// The blobs the mutations start from.
fn seeds() -> Vec<Vec<u8>> {
    let h = Diagram::from_degrees(
        &[0.0, 30.0, 60.0, 90.0],
        &[0.0, 120.0, 240.0],
        &[
            vec![1.0, 2.0, 0.5, 0.0],
            vec![1.0, 0.1, 3.0, 1.0],
            vec![1.0, 1.0, 1.0, 1.0],
        ],
    )
    .unwrap();
    let s = Diagram::from_degrees(
        &[0.0, 60.0, 120.0, 180.0],
        &[0.0, 90.0],
        &[vec![1.0, 2.0, 0.5, 0.2], vec![1.0, 0.1, 3.0, 0.2]],
    )
    .unwrap();
    let hm = HemisphereMap::new(&h).unwrap();
    let split = SphereMap::with_layout(&s, SphereLayout::Split).unwrap();
    let lambert = SphereMap::with_layout(&s, SphereLayout::Lambert).unwrap();
    let mut v = Vec::new();
    for p in [Precision::F32, Precision::F64] {
        let cases = [
            (MapRef::Hemisphere(&hm), Frame::Generic, Target::Grid(&h)),
            (MapRef::Sphere(&split), Frame::Photometric, Target::Grid(&s)),
        ];
        for (map, frame, target) in cases {
            v.push(blob::write(map, p, frame, &target).unwrap());
        }
        let rgb = vec![0.5f32; 4 * 2 * 3];
        let img = Target::Image {
            width: 4,
            height: 2,
            rgb: &rgb,
            lookup: Default::default(),
        };
        v.push(blob::write(MapRef::Sphere(&lambert), p, Frame::EnvironmentMap, &img).unwrap());
    }
    v
}

fn exercise(t: &blob::MapTables, data: &[u8]) {
    let mut pts: Vec<[f64; 2]> = vec![[0.0, 0.0], [1.0, 1.0], [0.5, 0.5], [1.0, 0.0], [0.0, 1.0]];
    for c in data.chunks_exact(2).take(16) {
        pts.push([c[0] as f64 / 255.0, c[1] as f64 / 255.0]);
    }
    for u in pts {
        blob_case::assert_sane_sample(t, u);
        let _ = t.target_pdf(t.sample(u).direction);
    }
    for d in [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [f64::NAN, 0.0, 1.0],
    ] {
        blob_case::assert_sane_direction(t, d);
    }
    if let ReadMap::F32(f) = &t.map {
        let target = match &t.target {
            blob::TargetTables::None => Target::None,
            blob::TargetTables::Grid(g) => Target::Grid(g),
            blob::TargetTables::Image {
                width,
                height,
                rgb,
                lookup,
            } => Target::Image {
                width: *width,
                height: *height,
                rgb,
                lookup: *lookup,
            },
        };
        let again = blob::write_float32(f, t.frame, &target).expect("an accepted blob writes back");
        let back = blob::read(&again).expect("a rewritten blob reads");
        assert_eq!(back.grids, t.grids);
    }
}

fuzz_target!(|data: &[u8]| {
    // The input as a blob of its own.
    if let Ok(t) = blob::read(data) {
        exercise(&t, data);
    }
    // The input as a mutation of a seed blob, resealed.
    if let Some((b, rest)) = blob_case::mutated(seeds, data) {
        if let Ok(t) = blob::read(&b) {
            exercise(&t, rest);
        }
    }
});
