//! Temporary output files are removed when the process is interrupted.
//!
//! [`install`] sets a handler for SIGINT, SIGTERM and SIGHUP that unlinks every registered
//! temporary file (`unlink` is async-signal-safe), restores the default action and raises the
//! signal again, so the process still ends the way the signal says (exit status 128 + signal for a
//! shell). [`register`] records a temporary file; dropping the returned [`TempGuard`] forgets it.
//! SIGKILL cannot be caught: a killed run can leave a `.NAME.gonio-tmp-PID-K` file behind.

use std::path::Path;

/// Most temporary files registered at once (a command writes one output at a time).
#[cfg(unix)]
const SLOTS: usize = 8;

#[cfg(unix)]
static TEMPS: [std::sync::atomic::AtomicPtr<libc::c_char>; SLOTS] =
    [const { std::sync::atomic::AtomicPtr::new(std::ptr::null_mut()) }; SLOTS];

/// A registered temporary file; dropping it forgets the file (it does not remove it).
#[derive(Debug)]
pub struct TempGuard {
    #[cfg(unix)]
    slot: Option<usize>,
}

/// Registers `path` for removal on SIGINT/SIGTERM/SIGHUP. With more than a few registered at
/// once, the extra ones are not registered (they are still removed on every error path).
pub fn register(path: &Path) -> TempGuard {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        use std::sync::atomic::Ordering;
        let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
            return TempGuard { slot: None };
        };
        let p = c.into_raw();
        for (k, slot) in TEMPS.iter().enumerate() {
            if slot
                .compare_exchange(std::ptr::null_mut(), p, Ordering::SeqCst, Ordering::SeqCst)
                .is_ok()
            {
                return TempGuard { slot: Some(k) };
            }
        }
        // No free slot: give the string back.
        // SAFETY: `p` came from `CString::into_raw` above and was not shared.
        drop(unsafe { std::ffi::CString::from_raw(p) });
        TempGuard { slot: None }
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        TempGuard {}
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        #[cfg(unix)]
        if let Some(k) = self.slot {
            // The string is deliberately leaked (a few bytes per output file): a signal handler
            // running on another thread may still be reading it.
            TEMPS[k].store(std::ptr::null_mut(), std::sync::atomic::Ordering::SeqCst);
        }
    }
}

#[cfg(unix)]
extern "C" fn on_signal(sig: libc::c_int) {
    for slot in &TEMPS {
        let p = slot.load(std::sync::atomic::Ordering::SeqCst);
        if !p.is_null() {
            // SAFETY: `p` is a NUL-terminated string that is never freed; unlink is
            // async-signal-safe.
            unsafe {
                libc::unlink(p);
            }
        }
    }
    // SAFETY: signal and raise are async-signal-safe; the default action ends the process.
    unsafe {
        libc::signal(sig, libc::SIG_DFL);
        libc::raise(sig);
    }
}

/// Installs the handler (once, at start-up).
pub fn install() {
    #[cfg(unix)]
    for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        // SAFETY: a plain C handler that only calls async-signal-safe functions.
        unsafe {
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            libc::sigemptyset(&mut sa.sa_mask);
            sa.sa_flags = libc::SA_RESTART;
            // A signal ignored by the parent (e.g. SIGHUP under nohup) stays ignored.
            let mut old: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(sig, std::ptr::null(), &mut old) == 0
                && old.sa_sigaction == libc::SIG_IGN
            {
                continue;
            }
            libc::sigaction(sig, &sa, std::ptr::null_mut());
        }
    }
}
