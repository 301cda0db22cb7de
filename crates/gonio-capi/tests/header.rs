//! The committed header `include/gonio.h` is what cbindgen generates from `src/lib.rs` now.
//!
//! Regenerate it with `GONIO_BLESS=1 cargo test -p gonio-capi --test header` after changing the
//! ABI, and commit the result.

use std::path::PathBuf;

#[test]
fn committed_header_is_current() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .expect("cbindgen.toml is readable");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("the header is UTF-8");
    let path = crate_dir.join("include/gonio.h");
    if std::env::var_os("GONIO_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("include/gonio.h is writable");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/gonio.h is stale: regenerate it with \
         `GONIO_BLESS=1 cargo test -p gonio-capi --test header` and commit it"
    );
    // The header declares every entry point the examples use.
    for f in [
        "gonio_diagram_read_path",
        "gonio_diagram_read_memory",
        "gonio_sampler_build",
        "gonio_sample_batch_soa_f32",
        "gonio_invert_batch",
        "gonio_last_error_message",
    ] {
        assert!(generated.contains(f), "{f} is missing from the header");
    }
}
