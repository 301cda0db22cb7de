//! The shared environment maps (`shared/data/envmaps`: studio, sunset, night, 1024 × 512 RGBE):
//! read, built, and a quick consistency check (sample/pdf/invert, normalisation by Monte Carlo).
//! Marked ignored when the maps are absent (set `GONIO_ENVMAPS` and rebuild).

#[path = "common/corpus.rs"]
mod corpus;

use gonio::envmap::EnvironmentMap;
use gonio::image::Image;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[test]
#[cfg_attr(
    not(gonio_envmaps),
    ignore = "shared environment maps not found (set GONIO_ENVMAPS)"
)]
fn the_shared_maps_read_build_and_sample_exactly() {
    let files = corpus::built_envmaps();
    assert!(files.len() >= 3, "{files:?}");
    for f in files {
        let img = Image::read(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert_eq!((img.width(), img.height()), (1024, 512), "{}", f.display());
        assert!(img.rgb().iter().all(|v| v.is_finite() && *v >= 0.0));
        assert!(img.rgb().iter().any(|&v| v > 0.0));
        // The file re-encoded and read back gives the same pixels (RGBE is lossless for RGBE values).
        let again = gonio::image::read_hdr(&gonio::image::write_hdr(&img)).unwrap();
        assert_eq!(again.rgb(), img.rgb(), "{}", f.display());
        let env = EnvironmentMap::new(img).unwrap();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        for _ in 0..20_000 {
            let u = [rng.gen(), rng.gen()];
            let s = env.sample(u);
            assert!(s.pdf > 0.0);
            assert!((env.pdf(s.direction) - s.pdf).abs() <= 1e-9 * s.pdf);
            let b = env.invert(s.direction).unwrap();
            assert!(
                (b[0] - u[0]).abs() < 1e-6 && (b[1] - u[1]).abs() < 1e-6,
                "{u:?} {b:?}"
            );
        }
        // ∫ pdf dω = 1 by uniform directions: 4π·mean(pdf), within 5 standard errors.
        let n = 200_000;
        let mut xs = Vec::with_capacity(n);
        for _ in 0..n {
            let z: f64 = rng.gen_range(-1.0..1.0);
            let p: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            xs.push(4.0 * std::f64::consts::PI * env.pdf([r * p.cos(), r * p.sin(), z]));
        }
        let m = xs.iter().sum::<f64>() / n as f64;
        let se = (xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n * (n - 1)) as f64).sqrt();
        assert!(
            (m - 1.0).abs() < 5.0 * se,
            "{}: ∫pdf = {m} ± {se}",
            f.display()
        );
    }
}
