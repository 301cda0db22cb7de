//! The table blob (docs/TABLES.md) through the C ABI: the map's tables as bytes in the caller's
//! buffer, for `gonio_device.h`, a GPU copy or a renderer's own loader.

use super::envmap::GonioEnvMap;
use super::*;
use gonio::mapping::blob::{self, Frame, Precision, Target};

/// The blob's precision from the C argument (4: f32, 8: f64).
fn precision(p: u32) -> Result<Precision, Failure> {
    match p {
        4 => Ok(Precision::F32),
        8 => Ok(Precision::F64),
        _ => Err(Failure::invalid(format!(
            "precision {p}: must be 4 (float32 tables) or 8 (float64 tables)"
        ))),
    }
}

/// Copies `bytes` into the caller's buffer (or answers the size only).
///
/// # Safety
/// As [`gonio_sampler_tables`]'s `buffer`, `capacity` and `size`.
unsafe fn deliver(
    bytes: &[u8],
    buffer: *mut u8,
    capacity: usize,
    size: *mut usize,
) -> Result<(), Failure> {
    w(size, bytes.len(), "size")?;
    if buffer.is_null() {
        return Ok(());
    }
    if capacity < bytes.len() {
        return Err(Failure::invalid(format!(
            "the buffer holds {capacity} bytes; the tables need {} (`*size`)",
            bytes.len()
        )));
    }
    std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer, bytes.len());
    Ok(())
}

/// The body of every `*_tables` function: checks `size`, reads `precision`, makes the blob with
/// `make` and delivers it (or its size).
///
/// # Safety
/// As [`gonio_sampler_tables`]'s `buffer`, `capacity` and `size`.
unsafe fn tables_call(
    precision: u32,
    buffer: *mut u8,
    capacity: usize,
    size: *mut usize,
    make: impl FnOnce(Precision) -> Result<Vec<u8>, Failure>,
) -> GonioStatus {
    guard(|| {
        check_out(size, "size")?;
        let bytes = make(self::precision(precision)?)?;
        deliver(&bytes, buffer, capacity, size)
    })
}

/// The blob writer's error as the C ABI's.
fn invalid(e: blob::TablesError) -> Failure {
    Failure::invalid(e.to_string())
}

/// The HDS map's tables of `sampler` as one blob (docs/TABLES.md, layout version 1), with the
/// diagram `target` as its grid target (NULL: none; its frame is photometric for IES and
/// EULUMDAT files, generic otherwise). `precision` is 4 (the float32 map, what
/// `gonio_device.h` samples) or 8 (the f64 map's tables).
///
/// Call it with `buffer` NULL to get the size in `*size`; then with a buffer of at least that
/// many bytes (64-byte aligned if the tables are to be used in place), which receives the blob.
/// [`GONIO_ERR_UNSUPPORTED`] for a sampler that is not the HDS method; [`GONIO_ERR_INVALID_ARGUMENT`]
/// for a bad precision, a buffer too small, or a grid too large for a float32 map.
///
/// # Safety
/// `sampler` and `target` NULL or live handles; `size` NULL or valid for writing a `size_t`;
/// `buffer` NULL or valid for writing `capacity` bytes.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_tables(
    sampler: *const GonioSampler,
    target: *const GonioDiagram,
    precision: u32,
    buffer: *mut u8,
    capacity: usize,
    size: *mut usize,
) -> GonioStatus {
    tables_call(precision, buffer, capacity, size, |p| {
        let s = r(sampler, "sampler")?;
        let map = s.inner.hds_map().ok_or_else(|| {
            Failure::new(
                GONIO_ERR_UNSUPPORTED,
                format!(
                    "the {} sampler has no tables: only the HDS map is written as a blob",
                    s.inner.name()
                ),
            )
        })?;
        let (t, frame) = if target.is_null() {
            (Target::None, Frame::Generic)
        } else {
            let d = r(target, "target")?;
            let frame = if d.photometry.is_some() {
                Frame::Photometric
            } else {
                Frame::Generic
            };
            (Target::Grid(&d.diagram), frame)
        };
        blob::write(map, p, frame, &t).map_err(invalid)
    })
}

/// The environment map's tables as one blob (docs/TABLES.md): its sphere map in `precision` (4 or
/// 8), in the environment map's lat-long frame, with its RGB image and radiance lookup as the
/// image target. Size query and buffer as [`gonio_sampler_tables`].
///
/// # Safety
/// `map` NULL or a live handle; `size` NULL or valid for writing a `size_t`; `buffer` NULL or
/// valid for writing `capacity` bytes.
#[no_mangle]
pub unsafe extern "C" fn gonio_envmap_tables(
    map: *const GonioEnvMap,
    precision: u32,
    buffer: *mut u8,
    capacity: usize,
    size: *mut usize,
) -> GonioStatus {
    tables_call(precision, buffer, capacity, size, |p| {
        blob::write_envmap(r(map, "map")?.inner(), p).map_err(invalid)
    })
}

/// The family blob of a BRDF sampler (docs/TABLES.md, "Families"): every incident slice's map in
/// `precision` (4 or 8) on their shared grid, the incident grid and the BRDF table, for a device
/// or a kernel that blends the slices as `gonio_brdf_sample` does. Size query and buffer as
/// [`gonio_sampler_tables`]. [`GONIO_ERR_UNSUPPORTED`] for a sampler that is not the "hds" method.
///
/// # Safety
/// `sampler` NULL or a live handle; `size` NULL or valid for writing a `size_t`; `buffer` NULL or
/// valid for writing `capacity` bytes.
#[no_mangle]
pub unsafe extern "C" fn gonio_brdf_sampler_tables(
    sampler: *const super::brdf::GonioBrdfSampler,
    precision: u32,
    buffer: *mut u8,
    capacity: usize,
    size: *mut usize,
) -> GonioStatus {
    tables_call(precision, buffer, capacity, size, |p| {
        let s = r(sampler, "sampler")?;
        let hds = s.hds().ok_or_else(|| {
            Failure::new(
                GONIO_ERR_UNSUPPORTED,
                "only the \"hds\" BRDF sampler has tables".to_string(),
            )
        })?;
        hds.tables(p).map_err(invalid)
    })
}
