//! Fuzz target: the BRDF readers (format recognised from the content: gonio BRDF JSON, UTIA raw,
//! MERL binary) must never panic; a table they accept must evaluate to finite values, and, when
//! small, build a sampler whose samples are finite with finite weights.
#![no_main]

use gonio::brdf::{read_any, BrdfSampler, IncidentSampler, MerlOptions, SamplerOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let merl = MerlOptions {
        n_theta: 4,
        n_phi: 4,
    };
    if let Ok(t) = read_any(data, &merl) {
        let wi = [0.3, 0.1, (1.0f64 - 0.1).sqrt()];
        let f = t.eval(wi, [0.0, 0.0, 1.0]);
        assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0));
        // Finite input gives finite output (issue 40: values of 1.7e308 gave albedo inf).
        assert!(t.values().iter().all(|v| v.is_finite() && *v >= 0.0));
        if t.values().len() > 4096 {
            return;
        }
        let opts = SamplerOptions {
            theta_o: 6,
            phi_o: 6,
            force_resample: false,
        };
        if let Ok(s) = BrdfSampler::new(t, &opts) {
            for u in [[0.1, 0.2], [0.9, 0.5], [0.5, 0.99]] {
                let smp = s.sample(wi, u);
                assert!(smp.pdf.is_finite() && smp.weight.iter().all(|w| w.is_finite()));
                assert!(smp.direction.iter().all(|c| c.is_finite()));
            }
            let albedo = IncidentSampler::new(&s, wi).albedo();
            assert!(albedo.is_finite() && albedo >= 0.0, "albedo {albedo}");
        }
    }
});
