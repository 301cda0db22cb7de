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
    let generated = c89_comments(&String::from_utf8(generated).expect("the header is UTF-8"));
    // C89 code may include the header (issue 25): no `//` comment anywhere.
    assert!(
        !generated.contains("//"),
        "a // comment is left in the header"
    );
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
        "gonio_brdf_read_memory",
        "gonio_brdf_sample_batch",
    ] {
        assert!(generated.contains(f), "{f} is missing from the header");
    }
}

/// cbindgen's own trailing comments (`#endif  // __cplusplus`, `}  // extern "C"`) are `//`
/// comments whatever the documentation style: rewritten as `/* … */` so that the header is C89.
fn c89_comments(header: &str) -> String {
    let mut out = String::with_capacity(header.len());
    for line in header.split_inclusive('\n') {
        let (body, nl) = match line.strip_suffix('\n') {
            Some(b) => (b, "\n"),
            None => (line, ""),
        };
        match body.find("//") {
            Some(k) => {
                let text = body[k + 2..].trim();
                out.push_str(body[..k].trim_end());
                out.push_str(&format!(" /* {text} */{nl}"));
            }
            None => out.push_str(line),
        }
    }
    out
}
