//! Fuzz target: the native JSON reader must never panic; whatever it accepts must survive a
//! write/read round trip with identical values, and (for small diagrams) build the HDS maps or
//! refuse cleanly.
#![no_main]

use gonio::{Diagram, HemisphereMap, SphereMap};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(d) = Diagram::from_json_str(text) else {
        return;
    };
    // Round trip through the JSON writer: same grid, same values, bit for bit (angles go through
    // degrees and back, so they are compared after one more round trip, which must be stable).
    let once = serde_json::to_string(&d.to_json()).expect("a diagram serialises");
    let back = Diagram::from_json_str(&once).expect("written JSON must read back");
    assert_eq!(back.values(), d.values());
    assert_eq!(back.theta().len(), d.theta().len());
    assert_eq!(back.phi().len(), d.phi().len());
    let twice = serde_json::to_string(&back.to_json()).expect("a diagram serialises");
    let again = Diagram::from_json_str(&twice).expect("written JSON must read back");
    assert_eq!(again.theta(), back.theta());
    assert_eq!(again.phi(), back.phi());
    if d.values().len() > 4096 {
        return;
    }
    let _ = d.integral();
    if *d.theta().last().expect("a diagram has parallels") <= std::f64::consts::FRAC_PI_2 {
        if let Ok(m) = HemisphereMap::new(&d) {
            let _ = gonio::Sampler::sample(&m, [0.5, 0.5]);
        }
    }
    if let Ok(m) = SphereMap::new(&d) {
        let _ = gonio::Sampler::sample(&m, [0.25, 0.75]);
    }
});
