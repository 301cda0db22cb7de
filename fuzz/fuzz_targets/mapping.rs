//! Fuzz target: the HDS maps on arbitrary small diagrams; the decoding of the input and the
//! properties checked are in `fuzz/common/mapping_case.rs` (shared with the regression test
//! `crates/gonio/tests/mapping_fuzz_cases.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../common/mapping_case.rs"]
mod mapping_case;

fuzz_target!(|data: &[u8]| mapping_case::run(data));
