//! The `mapping` fuzz target on stable Rust: its recorded findings (docs/FUZZING.md) replayed as
//! regression cases, and a seeded sweep of random inputs through the same decoder and checks
//! (`fuzz/common/mapping_case.rs`). Deterministic: the sweep's inputs come from a fixed seed.

use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[path = "../../../fuzz/common/mapping_case.rs"]
mod mapping_case;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex digits"))
        .collect()
}

fn to_hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

thread_local! {
    static IN_CASE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs every input, collecting the ones whose checks fail (with the failure's message).
fn failures<'a>(inputs: impl IntoIterator<Item = &'a [u8]>) -> Vec<String> {
    // The cases' panics are collected; keep them (and only them) off stderr.
    static QUIET: std::sync::Once = std::sync::Once::new();
    QUIET.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !IN_CASE.get() {
                default(info)
            }
        }))
    });
    let mut out = Vec::new();
    for data in inputs {
        IN_CASE.set(true);
        let result = std::panic::catch_unwind(|| mapping_case::run(data));
        IN_CASE.set(false);
        if let Err(e) = result {
            let msg = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            out.push(format!("{}: {msg}", to_hex(data)));
        }
    }
    out
}

/// The inputs the fuzzer found (docs/FUZZING.md): one-meridian sphere diagrams whose meridian is
/// off φ = 0 (seam round trip), a one-meridian diagram with zeros at the north pole (invert at +z),
/// subnormal-only light (pdf overflow), and the two early findings at u = (0, 0).
const FINDINGS: &[&str] = &[
    "800004ffff00ff0080050d2a2ad8",
    "0300960000009600960000009600",
    "d901954d00ffffff00ffff1023d8",
    "a3010053010300006c96a35304",
];

#[test]
fn recorded_fuzz_findings_hold() {
    let cases: Vec<Vec<u8>> = FINDINGS.iter().map(|h| hex(h)).collect();
    let bad = failures(cases.iter().map(Vec::as_slice));
    assert!(
        bad.is_empty(),
        "{} finding(s) fail:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn seeded_sweep_of_random_inputs_holds() {
    // 4,000 inputs of 0–48 random bytes (GONIO_FUZZ_CASES to run more); each builds up to three
    // maps of at most 9 x 9 nodes.
    let count = std::env::var("GONIO_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x6f6e_696f_6766_757a);
    let cases: Vec<Vec<u8>> = (0..count)
        .map(|_| {
            let n = rng.gen_range(0..=48);
            (0..n).map(|_| rng.gen::<u8>()).collect()
        })
        .collect();
    let bad = failures(cases.iter().map(Vec::as_slice));
    assert!(
        bad.is_empty(),
        "{} of {} inputs fail; first ones:\n{}",
        bad.len(),
        cases.len(),
        bad.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
}
