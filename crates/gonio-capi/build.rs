//! The shared library's SONAME: `libgonio.so.0.MINOR` while the version is 0.x (a 0.x minor
//! release may change the ABI), `libgonio.so.MAJOR` from 1.0 on. `scripts/install-c.sh` installs
//! `libgonio_capi.so` as `libgonio.so.VERSION` with these two names linked to it, so that a program
//! linked against `-lgonio` records the SONAME and finds the library in an installed prefix.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if !matches!(
        os.as_str(),
        "linux" | "android" | "freebsd" | "netbsd" | "openbsd" | "dragonfly"
    ) {
        return;
    }
    let major = std::env::var("CARGO_PKG_VERSION_MAJOR").unwrap_or_else(|_| "0".into());
    let minor = std::env::var("CARGO_PKG_VERSION_MINOR").unwrap_or_else(|_| "0".into());
    let soname = if major == "0" {
        format!("libgonio.so.0.{minor}")
    } else {
        format!("libgonio.so.{major}")
    };
    println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,{soname}");
}
