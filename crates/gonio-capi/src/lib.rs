//! # gonio-capi — the C ABI of gonio
//!
//! A shared (`libgonio_capi.so`) and a static (`libgonio_capi.a`) library with the header
//! `include/gonio.h`, generated from this file by cbindgen. It reads IES LM-63, EULUMDAT and
//! native JSON diagrams, builds a sampler of any method and domain through the library's factory,
//! and samples, evaluates the pdf, inverts and evaluates the target density one point at a time or
//! in batches (f64 and f32, array-of-structs and structure-of-arrays). `docs/C_API.md` is the
//! user's guide; the rules in short:
//!
//! * **Handles** are opaque: a [`GonioDiagram`] (a read file) and a [`GonioSampler`]. Each is
//!   created by one function and released by its `*_free` function (which accepts NULL). A sampler
//!   does not borrow the diagram it was built from: the diagram may be freed first.
//! * **Errors**: every function that can fail returns a [`GonioStatus`] ([`GONIO_OK`] = 0) and
//!   leaves a message for [`gonio_last_error_message`] in a thread-local buffer: the same text as
//!   the `gonio` CLI prints, e.g. `lamp.ies:12:5: expected a number, found "x"`.
//! * **No panic crosses the boundary**: each entry point catches one and returns
//!   [`GONIO_ERR_PANIC`] (a bug of gonio; the message says where).
//! * **Pointers** are checked for NULL and for the alignment of their type before use; outputs are
//!   written only on success, except that batch functions may have written part of their output
//!   when they fail. A batch reads the inputs of a chunk of 256 elements before it writes their
//!   outputs, so an output may overwrite its own or an earlier element's input (in place).
//! * **Threads**: a [`GonioSampler`] and a [`GonioDiagram`] are immutable after creation; any
//!   number of threads may use one handle at the same time. Freeing must not race with use.
//! * **Frames and units**: directions are `[x, y, z]` in gonio's frame (θ from +z, φ from +x toward
//!   +y; for photometric files the luminaire's nadir γ = 0° is −z and the C0 plane is +x), given
//!   as any finite non-zero vector (normalised internally); densities are per steradian; flux is
//!   in lumens for photometric files (candela × sr).
#![warn(missing_docs)]

mod handles;
pub use handles::*;
mod calls;
pub use calls::*;
mod batch;
pub use batch::*;

mod brdf;
pub use brdf::*;
mod envmap;
pub use envmap::*;
mod tables;
pub use tables::*;

#[cfg(test)]
mod test_support;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_abuse;
