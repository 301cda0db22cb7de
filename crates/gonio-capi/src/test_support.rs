//! What the C ABI's tests share: a small IES file, the thread's last error message, and a
//! diagram read from memory.

use super::*;
use std::ffi::CStr;
use std::ptr::{null, null_mut};

/// A type C IES file: 3 vertical angles, 1 plane (rotationally symmetric), a downlight.
pub(crate) const IES: &str =
    "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n0 45 90\n0\n100 60 0\n";

/// The calling thread's last error message.
pub(crate) fn last_error() -> String {
    unsafe { CStr::from_ptr(gonio_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// The diagram of `text` in `format`, read through `gonio_diagram_read_memory` (asserted to
/// succeed); the caller frees it.
pub(crate) fn diagram_of(text: &str, format: GonioFormat) -> *mut GonioDiagram {
    let mut d = null_mut();
    let st =
        unsafe { gonio_diagram_read_memory(text.as_ptr(), text.len(), format, null(), &mut d) };
    assert_eq!(st, GONIO_OK, "{}", last_error());
    d
}
