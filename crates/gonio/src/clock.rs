//! The one CPU-time clock of the workspace, for the benchmarks and the speed experiments: CPU time
//! does not count the time a thread spends descheduled on a shared machine, so it is the steadier
//! measure of a per-sample cost. (Speed is shown by benchmarks, never asserted by tests.)
//!
//! Both functions are `clock_gettime` on 64-bit Linux and return `None` elsewhere, where callers
//! fall back to wall time.

/// `clock_gettime` clock id of the calling process's CPU time (all threads).
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
/// `clock_gettime` clock id of the calling thread's CPU time.
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

/// CPU time of the calling thread in nanoseconds (`CLOCK_THREAD_CPUTIME_ID`), or `None` where the
/// OS does not report it.
///
/// ```
/// if let (Some(a), Some(b)) = (gonio::clock::thread_cpu_ns(), gonio::clock::thread_cpu_ns()) {
///     assert!(b >= a);
/// }
/// ```
pub fn thread_cpu_ns() -> Option<u64> {
    #[cfg(all(target_os = "linux", target_pointer_width = "64"))]
    {
        cpu_ns(CLOCK_THREAD_CPUTIME_ID)
    }
    #[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
    {
        None
    }
}

/// CPU time of the whole process (all threads together) in nanoseconds
/// (`CLOCK_PROCESS_CPUTIME_ID`), or `None` where the OS does not report it.
pub fn process_cpu_ns() -> Option<u64> {
    #[cfg(all(target_os = "linux", target_pointer_width = "64"))]
    {
        cpu_ns(CLOCK_PROCESS_CPUTIME_ID)
    }
    #[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
    {
        None
    }
}

/// `clock_gettime(clock)` in nanoseconds.
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn cpu_ns(clock: i32) -> Option<u64> {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
    }
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `ts` is a valid, writable `struct timespec` (two 64-bit fields on 64-bit Linux).
    let rc = unsafe { clock_gettime(clock, &mut ts) };
    (rc == 0).then(|| ts.sec as u64 * 1_000_000_000 + ts.nsec as u64)
}
