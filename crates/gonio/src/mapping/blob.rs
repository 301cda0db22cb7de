//! Tables → bytes: an HDS map's tables in one documented, versioned, little-endian layout
//! (`docs/TABLES.md`), so that a C, CUDA or Dr.Jit program samples the map in place, and the
//! validated reader that turns such bytes back into a map.
//!
//! One layout serves f32 and f64 tables, the hemisphere and both sphere layouts, luminaires,
//! JSON diagrams and environment maps. A blob holds:
//!
//! * a 256-byte header: magic `GONIOTAB`, layout version, the sizes, an FNV-1a 64 checksum of
//!   the whole, the precision (4 or 8 bytes per float), the domain and sphere layout, the frame
//!   (generic, photometric, environment map), the target kind, P_lower and 1/(2T), and two map
//!   descriptors (grid counts and the scalar parameters of each map);
//! * a directory: one 32-byte entry per table (id, element type, byte offset, count);
//! * the tables, each starting on a 64-byte boundary.
//!
//! [`write()`] makes a blob from a map ([`MapRef`]); [`read`] validates every field and table
//! (sizes against the bytes present before anything is allocated, offsets in range and aligned,
//! monotone tables, finite values, guide entries in range, the checksum) and answers a typed
//! [`TablesError`], never a panic. A map read back samples bit for bit as the one that wrote it:
//! an f32 blob is the writer's [`Float32Map`], an f64 blob its [`Float64Map`].

// The two map slots are indexed in step across several arrays.
#![allow(clippy::needless_range_loop)]

use super::angular::Angular;
use super::float32::{Layout, Maps};
use super::hds::Tables;
use super::radial::Radial;
use super::split::SplitRule;
use super::MapRef;
use super::{Float32Map, Float32MapError, Float64Map, FLOAT32_MAX_NODES};
use crate::envmap::Lookup;
use crate::Diagram;

mod family;
pub use family::{read_family, write_family, BrdfTable, FamilyTables, LAYOUT_FAMILY, TARGET_BRDF};

/// The first eight bytes of every blob.
pub const MAGIC: [u8; 8] = *b"GONIOTAB";
/// The layout version this library writes and reads.
pub const VERSION: u32 = 1;
/// Bytes of the fixed header (the directory follows it).
pub const HEADER_BYTES: usize = 256;
/// Bytes of one directory entry.
pub const ENTRY_BYTES: usize = 32;
/// Every table starts at a multiple of this many bytes (and the blob's length is one).
pub const ALIGN: usize = 64;
/// Byte offset of the checksum field (read as zero while the checksum is computed).
pub const CHECKSUM_OFFSET: usize = 24;
/// Byte offset of the first of the two map descriptors.
const SLOT_OFFSET: usize = 96;
/// Bytes of one map descriptor.
const SLOT_BYTES: usize = 80;

/// The element type of a blob's float tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// IEEE binary32: the float32 map ([`Float32Map`]).
    F32,
    /// IEEE binary64: the f64 map's own tables ([`Float64Map`]).
    F64,
}

impl Precision {
    /// Bytes per float: 4 or 8 (the header's `precision` field).
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
    /// `f32` or `f64`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// What the directions of a blob mean (the header's `frame` field). The map's axes are always
/// gonio's: θ from +z, φ from +x toward +y; the frame says what the data's angles are there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// A diagram given in gonio's frame (a JSON diagram, a synthetic one).
    Generic = 0,
    /// A photometric file: γ = π − θ (nadir along −z), C = φ; target values in candela.
    Photometric = 1,
    /// An environment map's lat-long frame (`docs/ENVMAPS.md`, "The frame"): the image's top
    /// row at +z, its centre column along +x, φ = π − 2π·s.
    EnvironmentMap = 2,
}

impl Frame {
    fn from_u32(v: u32) -> Option<Frame> {
        [Frame::Generic, Frame::Photometric, Frame::EnvironmentMap]
            .into_iter()
            .find(|f| *f as u32 == v)
    }
    /// `generic`, `photometric` or `environment-map`.
    pub fn name(self) -> &'static str {
        match self {
            Frame::Generic => "generic",
            Frame::Photometric => "photometric",
            Frame::EnvironmentMap => "environment-map",
        }
    }
}

/// The map's layout (the header's `layout` field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlobLayout {
    /// One hemisphere map (z ≥ 0).
    Hemisphere = 0,
    /// One map over the whole sphere (Lambert).
    SphereLambert = 1,
    /// The split sphere: a lower and an upper hemisphere map and P_lower.
    SphereSplit = 2,
}

/// What a blob carries beside the map to evaluate the distribution it samples (the header's
/// `target` field), borrowed for [`write()`].
#[derive(Debug, Clone, Copy)]
pub enum Target<'a> {
    /// The map alone.
    None,
    /// A diagram's grid and values: the target value at a direction is
    /// [`Diagram::interpolate`] (bilinear in θ and φ, periodic in φ, 0 outside [θ_0, θ_{N−1}]);
    /// candela for a photometric file.
    Grid(&'a Diagram),
    /// An environment map's linear RGB image (row 0 at the top) and its radiance lookup.
    Image {
        /// Pixels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// `width × height` RGB triples, row-major.
        rgb: &'a [f32],
        /// The radiance lookup the environment map uses.
        lookup: Lookup,
    },
}

/// The target a blob carried, read back.
#[derive(Debug, Clone)]
pub enum TargetTables {
    /// None.
    None,
    /// A diagram (validated as [`Diagram::new`] does), stored in f64 in every blob.
    Grid(Diagram),
    /// An environment map's image.
    Image {
        /// Pixels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// RGB triples, row-major, row 0 at the top.
        rgb: Vec<f32>,
        /// The radiance lookup.
        lookup: Lookup,
    },
}

/// Why bytes are not a valid table blob.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TablesError {
    /// Fewer bytes than the header or the size it states.
    #[error("table blob: {present} bytes, but {needed} are needed ({what})")]
    Truncated {
        /// What needed them.
        what: &'static str,
        /// Bytes needed.
        needed: u64,
        /// Bytes present.
        present: u64,
    },
    /// The first eight bytes are not `GONIOTAB`.
    #[error("table blob: bytes 0-7 are not the magic \"GONIOTAB\"")]
    Magic,
    /// A layout version this library does not read.
    #[error("table blob: layout version {found} (this library reads version {VERSION})")]
    Version {
        /// The version found.
        found: u32,
    },
    /// A header field out of its range.
    #[error("table blob: header field {field} at byte {offset} is {value}: {why}")]
    Field {
        /// The field's name (docs/TABLES.md).
        field: &'static str,
        /// Its byte offset.
        offset: usize,
        /// Its value (floats as their value, rounded for the message).
        value: String,
        /// What is wrong.
        why: &'static str,
    },
    /// The stored checksum differs from that of the bytes.
    #[error("table blob: checksum {stored:#018x} stored, {computed:#018x} computed: the bytes were changed")]
    Checksum {
        /// The header's value.
        stored: u64,
        /// FNV-1a 64 of the bytes.
        computed: u64,
    },
    /// A directory entry that is not the table expected at its place.
    #[error("table blob: directory entry {index} (byte {offset}), table {name}: {why}")]
    Entry {
        /// The entry's index.
        index: usize,
        /// Its byte offset.
        offset: usize,
        /// The table expected there.
        name: String,
        /// What is wrong.
        why: String,
    },
    /// A table whose contents break the map's invariants.
    #[error("table blob: table {name}, entry {at}: {why}")]
    Content {
        /// The table's name (docs/TABLES.md).
        name: String,
        /// The entry's index within the table.
        at: usize,
        /// What is wrong.
        why: String,
    },
    /// The map has no float32 map (its grid is beyond the float32 kernels' limits).
    #[error(transparent)]
    Float32(#[from] Float32MapError),
    /// The target does not fit the layout (an image whose size and buffer disagree).
    #[error("table blob: {0}")]
    Target(String),
}

/// FNV-1a 64 of `bytes` with the eight checksum bytes (24..32) read as zero: the blob's
/// checksum.
pub fn checksum(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for (k, &b) in bytes.iter().enumerate() {
        let b = if (CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8).contains(&k) {
            0
        } else {
            b
        };
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

// ------------------------------------------------------------------------------------------
// Table ids and the expected directory.
// ------------------------------------------------------------------------------------------

/// Element types of the directory (`elem` field).
const ELEM_F32: u32 = 1;
const ELEM_F64: u32 = 2;
const ELEM_U32: u32 = 3;

/// The twelve tables of one map, in directory order: (name, is a u32 guide table).
pub const MAP_TABLES: [(&str, bool); 12] = [
    ("phi", false),
    ("beta", false),
    ("r2", false),
    ("cum", false),
    ("wedge_guide", true),
    ("x", false),
    ("d", false),
    ("u", false),
    ("total", false),
    ("radius_guide", true),
    ("inv_dx", false),
    ("radial_guide", true),
];
/// Id of table k of map slot s: 16·s + k.
fn map_table_id(slot: usize, k: usize) -> u32 {
    (16 * slot + k) as u32
}
/// Ids of the grid target's θ nodes, φ nodes and values.
const ID_GRID_THETA: u32 = 32;
const ID_GRID_PHI: u32 = 33;
const ID_GRID_VALUES: u32 = 34;
/// Id of the image target's RGB pixels.
const ID_IMAGE_RGB: u32 = 40;

/// Counts of one map's tables from its descriptor: (M, N, K, wedge guide, radius guide).
fn map_counts(m: u64, n: u64, k: u64, g: u64, rg: u64) -> [u64; 12] {
    [
        m + 1,
        m,
        m + 1,
        m + 1,
        g,
        n,
        m * n,
        m * n,
        m,
        rg,
        n - 1,
        m * (k + 1),
    ]
}

// ------------------------------------------------------------------------------------------
// Writing.
// ------------------------------------------------------------------------------------------

/// A float that a blob stores.
trait BlobFloat: Copy {
    fn put(self, out: &mut Vec<u8>);
    fn as_f64(self) -> f64;
}
impl BlobFloat for f32 {
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn as_f64(self) -> f64 {
        f64::from(self)
    }
}
impl BlobFloat for f64 {
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn as_f64(self) -> f64 {
        self
    }
}

/// One table's bytes and its directory fields, before placement.
struct Pending {
    id: u32,
    elem: u32,
    count: u64,
    bytes: Vec<u8>,
}

fn floats<T: BlobFloat>(id: u32, elem: u32, v: &[T]) -> Pending {
    let mut bytes = Vec::with_capacity(std::mem::size_of_val(v));
    for &x in v {
        x.put(&mut bytes);
    }
    Pending {
        id,
        elem,
        count: v.len() as u64,
        bytes,
    }
}

fn guides(id: u32, v: &[u32]) -> Pending {
    let mut bytes = Vec::with_capacity(v.len() * 4);
    for &x in v {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    Pending {
        id,
        elem: ELEM_U32,
        count: v.len() as u64,
        bytes,
    }
}

fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}
fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}
fn put_f64(b: &mut [u8], at: usize, v: f64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

/// The tables of one slot and its descriptor bytes.
fn slot_tables<T: BlobFloat>(
    slot: usize,
    t: &Tables<T>,
    elem: u32,
) -> ([u8; SLOT_BYTES], Vec<Pending>) {
    let (a, r) = (&t.angular, &t.radial);
    let mut d = [0u8; SLOT_BYTES];
    put_u32(&mut d, 0, a.m as u32);
    put_u32(&mut d, 4, r.n as u32);
    put_u32(&mut d, 8, r.radial_k as u32);
    put_u32(&mut d, 12, a.wedge_guide.len() as u32);
    put_u32(&mut d, 16, r.radius_guide.len() as u32);
    put_f64(&mut d, 32, a.inv_uniform_beta.as_f64());
    put_f64(&mut d, 40, a.kappa.as_f64());
    put_f64(&mut d, 48, a.guide_scale.as_f64());
    put_f64(&mut d, 56, r.radius_scale.as_f64());
    put_f64(&mut d, 64, r.edge.as_f64());
    let id = |k| map_table_id(slot, k);
    let p = vec![
        floats(id(0), elem, &a.phi),
        floats(id(1), elem, &a.beta),
        floats(id(2), elem, &a.r2),
        floats(id(3), elem, &a.cum),
        guides(id(4), &a.wedge_guide),
        floats(id(5), elem, &r.x),
        floats(id(6), elem, &r.d),
        floats(id(7), elem, &r.u),
        floats(id(8), elem, &r.total),
        guides(id(9), &r.radius_guide),
        floats(id(10), elem, &r.inv_dx),
        guides(id(11), &r.radial_guide),
    ];
    (d, p)
}

fn write_maps<T: BlobFloat>(
    maps: &Maps<T>,
    precision: Precision,
    frame: Frame,
    target: &Target<'_>,
) -> Result<Vec<u8>, TablesError> {
    let elem = match precision {
        Precision::F32 => ELEM_F32,
        Precision::F64 => ELEM_F64,
    };
    let mut header = vec![0u8; HEADER_BYTES];
    header[..8].copy_from_slice(&MAGIC);
    put_u32(&mut header, 8, VERSION);
    put_u32(&mut header, 12, HEADER_BYTES as u32);
    put_u32(&mut header, 32, precision.bytes() as u32);
    put_u32(&mut header, 40, frame as u32);
    put_f64(&mut header, 72, maps.inv_2t.as_f64());
    let mut tables = Vec::new();
    let (layout, present, p_lower) = match &maps.layout {
        Layout::Hemisphere(t) | Layout::Lambert(t) => {
            let (d, p) = slot_tables(0, t, elem);
            header[SLOT_OFFSET..SLOT_OFFSET + SLOT_BYTES].copy_from_slice(&d);
            tables.extend(p);
            let l = if matches!(maps.layout, Layout::Hemisphere(_)) {
                BlobLayout::Hemisphere
            } else {
                BlobLayout::SphereLambert
            };
            (l, 1u32, 0.0)
        }
        Layout::Split { upper, lower, rule } => {
            let mut present = 0;
            for (slot, t) in [(0usize, lower), (1, upper)] {
                if let Some(t) = t {
                    let (d, p) = slot_tables(slot, t, elem);
                    let at = SLOT_OFFSET + slot * SLOT_BYTES;
                    header[at..at + SLOT_BYTES].copy_from_slice(&d);
                    tables.extend(p);
                    present |= 1 << slot;
                }
            }
            (BlobLayout::SphereSplit, present, rule.p_lower())
        }
    };
    put_u32(&mut header, 36, layout as u32);
    put_u32(&mut header, 56, present);
    put_f64(&mut header, 64, p_lower);
    match target {
        Target::None => {}
        Target::Grid(diagram) => {
            put_u32(&mut header, 44, 1);
            put_u32(&mut header, 88, diagram.theta().len() as u32);
            put_u32(&mut header, 92, diagram.phi().len() as u32);
            // The diagram exactly: f64 whatever the map's precision (θ = π rounded to f32 would
            // lie beyond the sphere).
            for (id, v) in [
                (ID_GRID_THETA, diagram.theta()),
                (ID_GRID_PHI, diagram.phi()),
                (ID_GRID_VALUES, diagram.values()),
            ] {
                tables.push(floats(id, ELEM_F64, v));
            }
            put_f64(&mut header, 80, diagram.integral());
        }
        Target::Image {
            width,
            height,
            rgb,
            lookup,
        } => {
            let ok = width
                .checked_mul(*height)
                .and_then(|p| p.checked_mul(3))
                .is_some_and(|c| c == rgb.len() && c > 0)
                && *width <= u32::MAX as usize
                && *height <= u32::MAX as usize;
            if !ok {
                return Err(TablesError::Target(format!(
                    "an image target of {width} × {height} pixels with {} floats",
                    rgb.len()
                )));
            }
            put_u32(&mut header, 44, 2);
            put_u32(&mut header, 60, *lookup as u32);
            put_u32(&mut header, 88, *width as u32);
            put_u32(&mut header, 92, *height as u32);
            tables.push(floats(ID_IMAGE_RGB, ELEM_F32, rgb));
        }
    }
    Ok(assemble(header, tables))
}

/// The blob of `header` (its table count, total size and checksum filled in here) and `tables`,
/// placed after the directory in order, each on a 64-byte boundary.
fn assemble(mut header: Vec<u8>, tables: Vec<Pending>) -> Vec<u8> {
    put_u32(&mut header, 48, tables.len() as u32);
    // Place the tables after the directory, each on a 64-byte boundary.
    let dir_end = HEADER_BYTES + ENTRY_BYTES * tables.len();
    let mut at = dir_end.next_multiple_of(ALIGN);
    let mut dir = vec![0u8; ENTRY_BYTES * tables.len()];
    let mut offsets = Vec::with_capacity(tables.len());
    for (k, t) in tables.iter().enumerate() {
        let e = k * ENTRY_BYTES;
        put_u32(&mut dir, e, t.id);
        put_u32(&mut dir, e + 4, t.elem);
        put_u64(&mut dir, e + 8, at as u64);
        put_u64(&mut dir, e + 16, t.count);
        offsets.push(at);
        at = (at + t.bytes.len()).next_multiple_of(ALIGN);
    }
    let total = at;
    put_u64(&mut header, 16, total as u64);
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&header);
    out.extend_from_slice(&dir);
    for (t, off) in tables.iter().zip(offsets) {
        out.resize(off, 0);
        out.extend_from_slice(&t.bytes);
    }
    out.resize(total, 0);
    let c = checksum(&out);
    put_u64(&mut out, CHECKSUM_OFFSET, c);
    out
}

/// The blob of `map`'s tables in `precision`, with `frame` and `target` (see the module
/// documentation and `docs/TABLES.md`). f32: the map's [`Float32Map`] (as
/// [`crate::HemisphereMap::float32_map`] builds it); f64: the map's own tables.
///
/// # Errors
/// [`TablesError::Float32`] for a grid beyond the float32 kernels' limits (f32 only);
/// [`TablesError::Target`] for an image target whose size and buffer disagree.
pub fn write(
    map: MapRef<'_>,
    precision: Precision,
    frame: Frame,
    target: &Target<'_>,
) -> Result<Vec<u8>, TablesError> {
    match precision {
        Precision::F32 => {
            let f = match map {
                MapRef::Hemisphere(h) => h.float32_map()?,
                MapRef::Sphere(s) => s.float32_map()?,
            };
            write_maps(&f.maps, precision, frame, target)
        }
        Precision::F64 => {
            let f = match map {
                MapRef::Hemisphere(h) => h.float64_map(),
                MapRef::Sphere(s) => s.float64_map(),
            };
            write_maps(&f.maps, precision, frame, target)
        }
    }
}

/// [`write()`] for a float32 map already built.
///
/// # Errors
/// As [`write()`].
pub fn write_float32(
    map: &Float32Map,
    frame: Frame,
    target: &Target<'_>,
) -> Result<Vec<u8>, TablesError> {
    write_maps(&map.maps, Precision::F32, frame, target)
}

/// The blob target of an environment map: its RGB image and radiance lookup.
fn image_target<'a>(
    image: &'a crate::image::Image,
    options: &crate::envmap::EnvOptions,
) -> Target<'a> {
    Target::Image {
        width: image.width(),
        height: image.height(),
        rgb: image.rgb(),
        lookup: options.lookup,
    }
}

/// An environment map's tables as one blob in `precision`, in its lat-long frame
/// ([`Frame::EnvironmentMap`]), with its RGB image and radiance lookup as the target: what the
/// CLI's `gonio tables`, Python's `EnvMap.tables` and the C ABI's `gonio_envmap_tables` write.
///
/// # Errors
/// As [`write()`].
pub fn write_envmap(
    env: &crate::envmap::EnvironmentMap,
    precision: Precision,
) -> Result<Vec<u8>, TablesError> {
    write(
        MapRef::Sphere(env.map()),
        precision,
        Frame::EnvironmentMap,
        &image_target(env.image(), env.options()),
    )
}

/// A float32 environment map's tables as one blob (precision f32), as [`write_envmap`] writes
/// them for the f64 map's float32 twin.
///
/// # Errors
/// As [`write_float32`].
pub fn write_envmap_float32(
    env: &crate::envmap::Float32EnvironmentMap,
) -> Result<Vec<u8>, TablesError> {
    write_float32(
        env.map(),
        Frame::EnvironmentMap,
        &image_target(env.image(), env.options()),
    )
}

// ------------------------------------------------------------------------------------------
// Reading.
// ------------------------------------------------------------------------------------------

/// A map read back from a blob: the float32 map or the f64 map's tables.
#[derive(Debug, Clone)]
pub enum ReadMap {
    /// An f32 blob.
    F32(Float32Map),
    /// An f64 blob.
    F64(Float64Map),
}

impl From<Maps<f32>> for ReadMap {
    fn from(maps: Maps<f32>) -> Self {
        ReadMap::F32(Float32Map { maps })
    }
}

impl From<Maps<f64>> for ReadMap {
    fn from(maps: Maps<f64>) -> Self {
        ReadMap::F64(Float64Map { maps })
    }
}

/// A validated blob, read back ([`read`]).
#[derive(Debug, Clone)]
pub struct MapTables {
    /// The map.
    pub map: ReadMap,
    /// The tables' precision.
    pub precision: Precision,
    /// The layout.
    pub layout: BlobLayout,
    /// The frame.
    pub frame: Frame,
    /// The target it carried.
    pub target: TargetTables,
    /// The grid of each map slot present: (M, N) for slot 0 (the map, or the lower map of a
    /// split sphere) and slot 1 (the upper map).
    pub grids: [Option<(usize, usize)>; 2],
    /// P_lower of a split sphere (0 otherwise).
    pub p_lower: f64,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}
fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}
fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// The header's u32 at `offset` (the field `name`) must be `want`, else [`TablesError::Field`].
fn expect_u32(
    bytes: &[u8],
    name: &'static str,
    offset: usize,
    want: u32,
    why: &'static str,
) -> Result<(), TablesError> {
    let v = u32_at(bytes, offset);
    if v != want {
        return Err(field(name, offset, v, why));
    }
    Ok(())
}

fn field(
    field: &'static str,
    offset: usize,
    value: impl ToString,
    why: &'static str,
) -> TablesError {
    TablesError::Field {
        field,
        offset,
        value: value.to_string(),
        why,
    }
}

fn content(name: &str, at: usize, why: impl Into<String>) -> TablesError {
    TablesError::Content {
        name: name.to_string(),
        at,
        why: why.into(),
    }
}

/// One expected table: (id, name, elem, count).
struct Expect {
    id: u32,
    name: String,
    elem: u32,
    count: u64,
}

/// A float the reader decodes.
trait ReadFloat: BlobFloat + PartialOrd + Default {
    const SIZE: usize;
    fn get(b: &[u8]) -> Self;
    /// `v` rounded to this type.
    fn of_f64(v: f64) -> Self;
    /// `v` as this type, when it is exactly representable.
    fn exact(v: f64) -> Option<Self>;
}
impl ReadFloat for f32 {
    const SIZE: usize = 4;
    fn get(b: &[u8]) -> Self {
        f32::from_le_bytes(b.try_into().expect("4 bytes"))
    }
    fn of_f64(v: f64) -> Self {
        v as f32
    }
    fn exact(v: f64) -> Option<Self> {
        let f = v as f32;
        (f64::from(f) == v || v.is_nan()).then_some(f)
    }
}
impl ReadFloat for f64 {
    const SIZE: usize = 8;
    fn get(b: &[u8]) -> Self {
        f64::from_le_bytes(b.try_into().expect("8 bytes"))
    }
    fn of_f64(v: f64) -> Self {
        v
    }
    fn exact(v: f64) -> Option<Self> {
        Some(v)
    }
}

/// The bytes of table `k` of the directory (already checked to lie within the blob).
struct Placed<'a> {
    bytes: &'a [u8],
}

fn read_floats<T: ReadFloat>(p: &Placed<'_>, name: &str) -> Result<Vec<T>, TablesError> {
    let v: Vec<T> = p.bytes.chunks_exact(T::SIZE).map(T::get).collect();
    if let Some(at) = v.iter().position(|x| !x.as_f64().is_finite()) {
        return Err(content(name, at, "not a finite number"));
    }
    Ok(v)
}

fn read_guides(p: &Placed<'_>, name: &str, max: u64) -> Result<Vec<u32>, TablesError> {
    let v: Vec<u32> = p
        .bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    if let Some(at) = v.iter().position(|&x| u64::from(x) > max) {
        return Err(content(
            name,
            at,
            format!("guide entry {} beyond its table's last index {max}", v[at]),
        ));
    }
    Ok(v)
}

fn non_negative<T: ReadFloat>(v: &[T], name: &str) -> Result<(), TablesError> {
    match v.iter().position(|x| x.as_f64() < 0.0) {
        Some(at) => Err(content(name, at, "negative")),
        None => Ok(()),
    }
}

fn non_decreasing<T: ReadFloat>(v: &[T], name: &str, base: usize) -> Result<(), TablesError> {
    match v.windows(2).position(|w| w[1] < w[0]) {
        Some(at) => Err(content(
            name,
            base + at + 1,
            "smaller than the entry before it",
        )),
        None => Ok(()),
    }
}

/// A scalar of a map descriptor: finite, ≥ 0, and exactly a value of the blob's precision.
fn scalar<T: ReadFloat>(
    b: &[u8],
    at: usize,
    name: &'static str,
    positive: bool,
) -> Result<T, TablesError> {
    let v = f64_at(b, at);
    if !v.is_finite() || v < 0.0 || (positive && v <= 0.0) {
        return Err(field(
            name,
            at,
            v,
            if positive {
                "must be finite and > 0"
            } else {
                "must be finite and >= 0"
            },
        ));
    }
    T::exact(v).ok_or_else(|| field(name, at, v, "not a value of the blob's precision"))
}

/// One slot's descriptor fields.
struct Slot {
    m: u64,
    n: u64,
    k: u64,
    g: u64,
    rg: u64,
}

fn read_slot(b: &[u8], slot: usize, f32_limits: bool) -> Result<Slot, TablesError> {
    let at = SLOT_OFFSET + slot * SLOT_BYTES;
    let m = u64::from(u32_at(b, at));
    let n = u64::from(u32_at(b, at + 4));
    let k = u64::from(u32_at(b, at + 8));
    let g = u64::from(u32_at(b, at + 12));
    let rg = u64::from(u32_at(b, at + 16));
    let names = [
        "map.m",
        "map.n",
        "map.radial_k",
        "map.wedge_guide_len",
        "map.radius_guide_len",
    ];
    let mins = [1u64, 2, 1, 1, 1];
    for (i, (v, min)) in [m, n, k, g, rg].into_iter().zip(mins).enumerate() {
        if v < min {
            return Err(field(
                names[i],
                at + 4 * i,
                v,
                "below its minimum (m ≥ 1, n ≥ 2, the others ≥ 1)",
            ));
        }
    }
    if f32_limits && (m >= FLOAT32_MAX_NODES as u64 || n >= FLOAT32_MAX_NODES as u64) {
        return Err(field(
            "map.m/map.n",
            at,
            format!("{m} × {n}"),
            "beyond the float32 kernels' 2^22 nodes",
        ));
    }
    for r in 20..32 {
        if b[at + r] != 0 {
            return Err(field(
                "map.reserved",
                at + r,
                b[at + r],
                "reserved bytes must be 0",
            ));
        }
    }
    Ok(Slot { m, n, k, g, rg })
}

/// The largest angle a map's azimuth table may hold: 2π and the round-off of its f32 value.
const MAX_AZIMUTH: f64 = std::f64::consts::TAU * (1.0 + 1e-6);

fn at_most<T: ReadFloat>(
    v: &[T],
    name: &str,
    base: usize,
    max: f64,
    why: &str,
) -> Result<(), TablesError> {
    match v.iter().position(|x| x.as_f64() > max) {
        Some(at) => Err(content(
            name,
            base + at,
            format!("{} exceeds {max}: {why}", v[at].as_f64()),
        )),
        None => Ok(()),
    }
}

/// `max_radius`: the disk radius of the map's edge (1 for a hemisphere map, √2 for the Lambert
/// sphere), `inv_2t` the pdf scale: every density times it must stay finite.
/// The scalar parameters of one map (a slot's descriptor, or a family slice's row).
struct Scalars<T> {
    inv_uniform_beta: T,
    kappa: T,
    guide_scale: T,
    radius_scale: T,
    edge: T,
}

/// The scalars of slot `slot`'s descriptor; `family`: κ and the edge are the slices' own (in
/// their table) and these fields must be 0.
/// What reading a blob's map needs besides the element type: its bytes, slots, placed tables
/// (each present slot's 12 in slot order), layout, split rule, largest disk radius and 1/(2T).
struct SlotsRead<'a> {
    bytes: &'a [u8],
    slots: &'a [Option<Slot>; 2],
    placed: &'a [Placed<'a>],
    layout: BlobLayout,
    rule: SplitRule,
    max_radius: f64,
    inv_2t: f64,
}

impl SlotsRead<'_> {
    /// The map in element type `T`: each present slot's scalars and tables, checked, in the
    /// blob's layout, 1/(2T) rounded to `T`.
    fn read<T: ReadFloat>(&self) -> Result<ReadMap, TablesError>
    where
        Maps<T>: Into<ReadMap>,
    {
        let mut t: [Option<Tables<T>>; 2] = [None, None];
        let mut first = 0;
        for s in 0..2 {
            if let Some(sl) = &self.slots[s] {
                let pre = if s == 0 { "map0." } else { "map1." };
                let sc = read_scalars::<T>(self.bytes, s, false)?;
                let placed = &self.placed[first..first + 12];
                t[s] = Some(read_tables::<T>(
                    pre,
                    sl,
                    sc,
                    placed,
                    self.max_radius,
                    self.inv_2t,
                )?);
                first += 12;
            }
        }
        let [t0, t1] = t;
        let layout = match self.layout {
            BlobLayout::Hemisphere => Layout::Hemisphere(t0.expect("slot 0")),
            BlobLayout::SphereLambert => Layout::Lambert(t0.expect("slot 0")),
            BlobLayout::SphereSplit => Layout::Split {
                lower: t0,
                upper: t1,
                rule: self.rule,
            },
        };
        Ok(Maps {
            layout,
            inv_2t: T::of_f64(self.inv_2t),
        }
        .into())
    }
}

fn read_scalars<T: ReadFloat>(
    b: &[u8],
    slot: usize,
    family: bool,
) -> Result<Scalars<T>, TablesError> {
    let at = SLOT_OFFSET + slot * SLOT_BYTES;
    let zero = |off: usize, name: &'static str| {
        let v = f64_at(b, at + off);
        if v != 0.0 || v.is_sign_negative() {
            return Err(field(name, at + off, v, "reserved bytes must be 0"));
        }
        Ok(T::default())
    };
    let inv_uniform_beta = scalar::<T>(b, at + 32, "map.inv_uniform_beta", false)?;
    let (kappa, edge) = if family {
        (zero(40, "map.kappa")?, zero(64, "map.edge")?)
    } else {
        let kappa = scalar::<T>(b, at + 40, "map.kappa", true)?;
        if !(0.5..=2.0).contains(&kappa.as_f64()) {
            return Err(field(
                "map.kappa",
                at + 40,
                kappa.as_f64(),
                "must be 1 up to round-off (the star domain has the disk's area)",
            ));
        }
        (kappa, scalar::<T>(b, at + 64, "map.edge", false)?)
    };
    let guide_scale = scalar::<T>(b, at + 48, "map.guide_scale", false)?;
    let radius_scale = scalar::<T>(b, at + 56, "map.radius_scale", false)?;
    zero(72, "map.reserved")?;
    Ok(Scalars {
        inv_uniform_beta,
        kappa,
        guide_scale,
        radius_scale,
        edge,
    })
}

/// One map's tables from their bytes `placed` (in [`MAP_TABLES`] order), checked; table names
/// in errors start with `pre`.
fn read_tables<T: ReadFloat>(
    pre: &str,
    s: &Slot,
    sc: Scalars<T>,
    placed: &[Placed<'_>],
    max_radius: f64,
    inv_2t: f64,
) -> Result<Tables<T>, TablesError> {
    let nm = |k: usize| format!("{pre}{}", MAP_TABLES[k].0);
    let Scalars {
        inv_uniform_beta,
        kappa,
        guide_scale,
        radius_scale,
        edge,
    } = sc;
    let (m, n) = (s.m as usize, s.n as usize);
    let phi = read_floats::<T>(&placed[0], &nm(0))?;
    non_decreasing(&phi, &nm(0), 0)?;
    non_negative(&phi[..1], &nm(0))?;
    at_most(&phi, &nm(0), 0, MAX_AZIMUTH, "azimuths lie in [0, 2π]")?;
    // The builder's exact ends: φ_0 = 0 and φ_M = 2π, Γ_0 = 0 and Γ_M = 2π (in the blob's
    // precision), and κ = 2π / Σγ = 1 up to round-off (the star domain has the disk's area).
    let tau = if T::SIZE == 4 {
        f64::from(std::f64::consts::TAU as f32)
    } else {
        std::f64::consts::TAU
    };
    let ends = |v: &[T], name: &str| -> Result<(), TablesError> {
        if v[0].as_f64() != 0.0 {
            return Err(content(name, 0, "must be 0"));
        }
        if v[m].as_f64() != tau {
            return Err(content(name, m, format!("must be 2π ({tau})")));
        }
        Ok(())
    };
    ends(&phi, &nm(0))?;
    let beta = read_floats::<T>(&placed[1], &nm(1))?;
    non_negative(&beta, &nm(1))?;
    at_most(&beta, &nm(1), 0, MAX_AZIMUTH, "a sector is at most 2π wide")?;
    let r2 = read_floats::<T>(&placed[2], &nm(2))?;
    non_negative(&r2, &nm(2))?;
    let cum = read_floats::<T>(&placed[3], &nm(3))?;
    non_negative(&cum[..1], &nm(3))?;
    non_decreasing(&cum, &nm(3), 0)?;
    ends(&cum, &nm(3))?;
    let wedge_guide = read_guides(&placed[4], &nm(4), s.m - 1)?;
    let x = read_floats::<T>(&placed[5], &nm(5))?;
    non_negative(&x[..1], &nm(5))?;
    non_decreasing(&x, &nm(5), 0)?;
    at_most(
        &x,
        &nm(5),
        0,
        max_radius * (1.0 + 1e-6),
        "beyond the map's disk (1 for a hemisphere map, √2 for the Lambert sphere)",
    )?;
    let d = read_floats::<T>(&placed[6], &nm(6))?;
    non_negative(&d, &nm(6))?;
    // Every density times 1/(2T) is a finite number of the blob's precision.
    let limit = if T::SIZE == 4 {
        f64::from(f32::MAX)
    } else {
        f64::MAX
    };
    at_most(
        &d,
        &nm(6),
        0,
        limit / inv_2t.max(1.0),
        "its pdf (density × inv_2t) would overflow",
    )?;
    let u = read_floats::<T>(&placed[7], &nm(7))?;
    for i in 0..m {
        let row = &u[i * n..(i + 1) * n];
        non_negative(&row[..1], &nm(7)).map_err(|_| content(&nm(7), i * n, "negative"))?;
        non_decreasing(row, &nm(7), i * n)?;
    }
    let total = read_floats::<T>(&placed[8], &nm(8))?;
    for i in 0..m {
        if total[i].as_f64() != u[i * n + n - 1].as_f64() {
            return Err(content(
                &nm(8),
                i,
                "differs from the last entry of its row of u",
            ));
        }
    }
    let radius_guide = read_guides(&placed[9], &nm(9), s.n - 2)?;
    let inv_dx = read_floats::<T>(&placed[10], &nm(10))?;
    non_negative(&inv_dx, &nm(10))?;
    let radial_guide = read_guides(&placed[11], &nm(11), s.n - 2)?;
    Ok(Tables {
        angular: Angular {
            m,
            phi,
            beta,
            inv_uniform_beta,
            r2,
            cum,
            kappa,
            wedge_guide,
            guide_scale,
        },
        radial: Radial {
            n,
            x,
            d,
            u,
            total,
            radius_guide,
            radius_scale,
            inv_dx,
            radial_guide,
            radial_k: s.k as usize,
            edge,
        },
    })
}

/// The checks every blob passes before its layout is read: size, magic, version, header size,
/// total size, alignment, checksum; answers the precision.
fn check_header(bytes: &[u8]) -> Result<Precision, TablesError> {
    let len = bytes.len() as u64;
    if bytes.len() < HEADER_BYTES {
        return Err(TablesError::Truncated {
            what: "the header",
            needed: HEADER_BYTES as u64,
            present: len,
        });
    }
    if bytes[..8] != MAGIC {
        return Err(TablesError::Magic);
    }
    let version = u32_at(bytes, 8);
    if version != VERSION {
        return Err(TablesError::Version { found: version });
    }
    let hb = u32_at(bytes, 12);
    if hb as usize != HEADER_BYTES {
        return Err(field("header_bytes", 12, hb, "must be 256"));
    }
    let total = u64_at(bytes, 16);
    if total != len {
        if total > len {
            return Err(TablesError::Truncated {
                what: "the size the header states",
                needed: total,
                present: len,
            });
        }
        return Err(field(
            "total_bytes",
            16,
            total,
            "differs from the bytes given (longer)",
        ));
    }
    if !total.is_multiple_of(ALIGN as u64) {
        return Err(field("total_bytes", 16, total, "not a multiple of 64"));
    }
    let stored = u64_at(bytes, CHECKSUM_OFFSET);
    let computed = checksum(bytes);
    if stored != computed {
        return Err(TablesError::Checksum { stored, computed });
    }
    let precision = match u32_at(bytes, 32) {
        4 => Precision::F32,
        8 => Precision::F64,
        v => return Err(field("precision", 32, v, "must be 4 (f32) or 8 (f64)")),
    };
    Ok(precision)
}

/// The directory checked against the tables `expect`ed (ids, element types, counts, offsets
/// aligned, in order, inside the blob): each table's bytes.
fn place<'a>(
    bytes: &'a [u8],
    expect: &[Expect],
    table_count: u64,
) -> Result<Vec<Placed<'a>>, TablesError> {
    let len = bytes.len() as u64;
    if table_count != expect.len() as u64 {
        return Err(field(
            "table_count",
            48,
            table_count,
            "differs from the tables the header's layout and target need",
        ));
    }
    let dir_end = HEADER_BYTES as u64 + ENTRY_BYTES as u64 * table_count;
    if dir_end > len {
        return Err(TablesError::Truncated {
            what: "the directory",
            needed: dir_end,
            present: len,
        });
    }
    let mut placed = Vec::with_capacity(expect.len());
    let mut prev_end = dir_end;
    for (k, e) in expect.iter().enumerate() {
        let at = HEADER_BYTES + k * ENTRY_BYTES;
        let bad = |why: String| TablesError::Entry {
            index: k,
            offset: at,
            name: e.name.clone(),
            why,
        };
        let (id, el, off, count) = (
            u32_at(bytes, at),
            u32_at(bytes, at + 4),
            u64_at(bytes, at + 8),
            u64_at(bytes, at + 16),
        );
        if id != e.id {
            return Err(bad(format!("id {id}, expected {}", e.id)));
        }
        if el != e.elem {
            return Err(bad(format!("element type {el}, expected {}", e.elem)));
        }
        if count != e.count {
            return Err(bad(format!(
                "{count} entries, the header's counts give {}",
                e.count
            )));
        }
        if u64_at(bytes, at + 24) != 0 {
            return Err(bad("reserved bytes must be 0".into()));
        }
        if off % ALIGN as u64 != 0 {
            return Err(bad(format!("offset {off} is not a multiple of 64")));
        }
        if off < prev_end {
            return Err(bad(format!("offset {off} overlaps the header, directory or table before it (ends at {prev_end})")));
        }
        let size = if el == ELEM_F64 { 8u64 } else { 4 };
        let end = count.checked_mul(size).and_then(|b| b.checked_add(off));
        match end {
            Some(end) if end <= len => {
                placed.push(Placed {
                    bytes: &bytes[off as usize..end as usize],
                });
                prev_end = end;
            }
            _ => {
                return Err(bad(format!(
                    "{count} entries at offset {off} run past the blob's {len} bytes"
                )))
            }
        }
    }
    Ok(placed)
}

/// Validates `bytes` as a table blob and reads it back (see the module documentation; every
/// check is listed in `docs/TABLES.md`).
///
/// # Errors
/// A [`TablesError`] naming the field, directory entry or table entry at fault.
pub fn read(bytes: &[u8]) -> Result<MapTables, TablesError> {
    let precision = check_header(bytes)?;
    let layout = match u32_at(bytes, 36) {
        0 => BlobLayout::Hemisphere,
        1 => BlobLayout::SphereLambert,
        2 => BlobLayout::SphereSplit,
        v => {
            return Err(field(
                "layout",
                36,
                v,
                "must be 0 (hemisphere), 1 (Lambert sphere) or 2 (split sphere); 3 (a family) is read by blob::read_family",
            ))
        }
    };
    let frame = Frame::from_u32(u32_at(bytes, 40))
        .ok_or_else(|| field("frame", 40, u32_at(bytes, 40), "must be 0, 1 or 2"))?;
    let target_kind = u32_at(bytes, 44);
    if target_kind > 2 {
        return Err(field(
            "target",
            44,
            target_kind,
            "must be 0 (none), 1 (grid) or 2 (image)",
        ));
    }
    let table_count = u32_at(bytes, 48) as u64;
    expect_u32(bytes, "reserved", 52, 0, "reserved bytes must be 0")?;
    let present = u32_at(bytes, 56);
    let lookup_code = u32_at(bytes, 60);
    let p_lower = f64_at(bytes, 64);
    let inv_2t = f64_at(bytes, 72);
    let target_total = f64_at(bytes, 80);
    let (tw, th) = (u64::from(u32_at(bytes, 88)), u64::from(u32_at(bytes, 92)));

    // The slots present and the split rule.
    let slots_present: Vec<usize> = match layout {
        BlobLayout::Hemisphere | BlobLayout::SphereLambert => {
            if present != 1 {
                return Err(field("maps_present", 56, present, "must be 1 for one map"));
            }
            if p_lower != 0.0 || p_lower.is_sign_negative() {
                return Err(field("p_lower", 64, p_lower, "must be 0 for one map"));
            }
            vec![0]
        }
        BlobLayout::SphereSplit => {
            let ok = match present {
                1 => p_lower == 1.0,
                2 => p_lower == 0.0 && !p_lower.is_sign_negative(),
                3 => p_lower > 0.0 && p_lower < 1.0,
                _ => false,
            };
            if !ok {
                return Err(field(
                    "maps_present/p_lower",
                    56,
                    format!("{present}/{p_lower}"),
                    "a split sphere has the lower map (bit 0) with P_lower = 1, the upper (bit 1) with 0, or both with 0 < P_lower < 1",
                ));
            }
            if precision == Precision::F32 && f64::from(p_lower as f32) != p_lower {
                return Err(field(
                    "p_lower",
                    64,
                    p_lower,
                    "not a value of the blob's precision",
                ));
            }
            (0..2).filter(|s| present & (1 << s) != 0).collect()
        }
    };
    if !(inv_2t.is_finite() && inv_2t > 0.0)
        || (precision == Precision::F32 && f64::from(inv_2t as f32) != inv_2t)
    {
        return Err(field(
            "inv_2t",
            72,
            inv_2t,
            "must be finite, > 0 and a value of the blob's precision",
        ));
    }
    let f32_limits = precision == Precision::F32;
    let mut slots: [Option<Slot>; 2] = [None, None];
    for s in 0..2 {
        let at = SLOT_OFFSET + s * SLOT_BYTES;
        if slots_present.contains(&s) {
            slots[s] = Some(read_slot(bytes, s, f32_limits)?);
        } else if let Some(r) = bytes[at..at + SLOT_BYTES].iter().position(|&x| x != 0) {
            return Err(field(
                "map descriptor",
                at + r,
                bytes[at + r],
                "a slot without a map must be all 0",
            ));
        }
    }
    let lookup = match (target_kind, lookup_code) {
        (2, 0) => Lookup::Nearest,
        (2, 1) => Lookup::Bilinear,
        (2, v) => {
            return Err(field(
                "lookup",
                60,
                v,
                "must be 0 (nearest) or 1 (bilinear)",
            ))
        }
        (_, 0) => Lookup::Nearest,
        (_, v) => return Err(field("lookup", 60, v, "must be 0 without an image target")),
    };
    match target_kind {
        0 => {
            if tw != 0 || th != 0 || target_total != 0.0 || target_total.is_sign_negative() {
                return Err(field(
                    "target fields",
                    80,
                    format!("{tw} × {th}, {target_total}"),
                    "must be 0 without a target",
                ));
            }
        }
        1 => {
            if tw == 0 || th == 0 {
                return Err(field(
                    "target_rows/cols",
                    88,
                    format!("{tw} × {th}"),
                    "a grid target needs ≥ 1 parallel and meridian",
                ));
            }
            if !(target_total.is_finite() && target_total >= 0.0) {
                return Err(field(
                    "target_integral",
                    80,
                    target_total,
                    "must be finite and >= 0",
                ));
            }
        }
        _ => {
            if tw == 0 || th == 0 {
                return Err(field(
                    "target_rows/cols",
                    88,
                    format!("{tw} × {th}"),
                    "an image target needs ≥ 1 pixel",
                ));
            }
            if target_total != 0.0 || target_total.is_sign_negative() {
                return Err(field(
                    "target_integral",
                    80,
                    target_total,
                    "must be 0 for an image target",
                ));
            }
        }
    }
    // The expected directory.
    let elem = match precision {
        Precision::F32 => ELEM_F32,
        Precision::F64 => ELEM_F64,
    };
    let mut expect: Vec<Expect> = Vec::new();
    for s in 0..2 {
        if let Some(sl) = &slots[s] {
            let counts = map_counts(sl.m, sl.n, sl.k, sl.g, sl.rg);
            for (k, (name, guide)) in MAP_TABLES.iter().enumerate() {
                expect.push(Expect {
                    id: map_table_id(s, k),
                    name: format!("map{s}.{name}"),
                    elem: if *guide { ELEM_U32 } else { elem },
                    count: counts[k],
                });
            }
        }
    }
    match target_kind {
        1 => {
            let elem = ELEM_F64;
            expect.push(Expect {
                id: ID_GRID_THETA,
                name: "target.theta".into(),
                elem,
                count: tw,
            });
            expect.push(Expect {
                id: ID_GRID_PHI,
                name: "target.phi".into(),
                elem,
                count: th,
            });
            expect.push(Expect {
                id: ID_GRID_VALUES,
                name: "target.values".into(),
                elem,
                count: tw * th,
            });
        }
        2 => expect.push(Expect {
            id: ID_IMAGE_RGB,
            name: "target.rgb".into(),
            elem: ELEM_F32,
            count: tw * th * 3,
        }),
        _ => {}
    }
    let placed = place(bytes, &expect, table_count)?;
    // The tables.
    let mut grids = [None, None];
    for s in 0..2 {
        if let Some(sl) = &slots[s] {
            grids[s] = Some((sl.m as usize, sl.n as usize));
        }
    }
    let max_radius = if layout == BlobLayout::SphereLambert {
        std::f64::consts::SQRT_2
    } else {
        1.0
    };
    let rule = match present {
        1 => SplitRule::lower_only(),
        2 => SplitRule::upper_only(),
        _ => SplitRule::both(p_lower),
    };
    let maps = SlotsRead {
        bytes,
        slots: &slots,
        placed: &placed,
        layout,
        rule,
        max_radius,
        inv_2t,
    };
    let map = match precision {
        Precision::F32 => maps.read::<f32>()?,
        Precision::F64 => maps.read::<f64>()?,
    };
    let first_target = 12 * slots_present.len();
    let target = match target_kind {
        1 => {
            let get = |k: usize, name: &str| -> Result<Vec<f64>, TablesError> {
                read_floats::<f64>(&placed[first_target + k], name)
            };
            let theta = get(0, "target.theta")?;
            let phi = get(1, "target.phi")?;
            let values = get(2, "target.values")?;
            let d = Diagram::new(theta, phi, values)
                .map_err(|e| content("target", 0, format!("not a valid diagram: {e}")))?;
            TargetTables::Grid(d)
        }
        2 => {
            let rgb = read_floats::<f32>(&placed[first_target], "target.rgb")?;
            non_negative(&rgb, "target.rgb")?;
            TargetTables::Image {
                width: tw as usize,
                height: th as usize,
                rgb,
                lookup,
            }
        }
        _ => TargetTables::None,
    };
    Ok(MapTables {
        map,
        precision,
        layout,
        frame,
        target,
        grids,
        p_lower,
    })
}

// ------------------------------------------------------------------------------------------
// A blob read back, as a sampler.
// ------------------------------------------------------------------------------------------

impl MapTables {
    /// The sampler's domain: the hemisphere for layout 0, else the sphere.
    pub fn domain(&self) -> crate::Domain {
        match self.layout {
            BlobLayout::Hemisphere => crate::Domain::Hemisphere,
            _ => crate::Domain::Sphere,
        }
    }

    /// One point through the map's own batch call (f32 blob: the point rounded to f32 and the
    /// result widened).
    fn sample_one(&self, u: [f64; 2]) -> ([f64; 3], f64) {
        match &self.map {
            ReadMap::F64(m) => {
                let (mut x, mut y, mut z, mut p) = ([0.0], [0.0], [0.0], [0.0]);
                m.sample_soa(&[u[0]], &[u[1]], [&mut x, &mut y, &mut z], &mut p);
                ([x[0], y[0], z[0]], p[0])
            }
            ReadMap::F32(m) => {
                let (mut x, mut y, mut z, mut p) = ([0f32], [0f32], [0f32], [0f32]);
                m.sample_soa(
                    &[u[0] as f32],
                    &[u[1] as f32],
                    [&mut x, &mut y, &mut z],
                    &mut p,
                );
                (
                    [f64::from(x[0]), f64::from(y[0]), f64::from(z[0])],
                    f64::from(p[0]),
                )
            }
        }
    }
}

/// A unit vector, or `None` for a zero or non-finite one.
fn unit(d: crate::Vec3) -> Option<crate::Vec3> {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    (n.is_finite() && n > 0.0).then(|| [d[0] / n, d[1] / n, d[2] / n])
}

/// A blob read back samples as the map that wrote it: `sample`, `pdf` and `invert` one point at
/// a time through the map's batch calls; the structure-of-arrays batches of the blob's precision
/// are the writer's bit for bit (f64 blob: the f64 map's `*_batch_soa`; f32 blob: its float32
/// map's `*_batch_soa_f32`). `target_pdf` is the grid target's interpolant over its integral (0
/// without a grid target); there is no ratio bound or refinement (they stay with the writer).
impl crate::Sampler for MapTables {
    fn name(&self) -> &'static str {
        "hds"
    }
    fn domain(&self) -> crate::Domain {
        MapTables::domain(self)
    }
    fn sample(&self, u: crate::Point2) -> crate::Sample {
        let (direction, pdf) = self.sample_one(u);
        crate::Sample { direction, pdf }
    }
    fn pdf(&self, direction: crate::Vec3) -> f64 {
        let Some(d) = unit(direction) else { return 0.0 };
        match &self.map {
            ReadMap::F64(m) => {
                let mut p = [0.0];
                m.pdf_soa([&[d[0]], &[d[1]], &[d[2]]], &mut p);
                p[0]
            }
            ReadMap::F32(m) => {
                let mut p = [0f32];
                m.pdf_soa([&[d[0] as f32], &[d[1] as f32], &[d[2] as f32]], &mut p);
                f64::from(p[0])
            }
        }
    }
    fn invert(&self, direction: crate::Vec3) -> Result<crate::Point2, crate::InvertError> {
        let d = unit(direction).ok_or(crate::InvertError::OutsideDomain)?;
        if self.layout == BlobLayout::Hemisphere && d[2] < 0.0 {
            return Err(crate::InvertError::OutsideDomain);
        }
        if crate::Sampler::pdf(self, d) == 0.0 {
            return Err(crate::InvertError::ZeroDensity);
        }
        let uv = match &self.map {
            ReadMap::F64(m) => {
                let (mut u, mut v) = ([0.0], [0.0]);
                m.invert_soa([&[d[0]], &[d[1]], &[d[2]]], [&mut u, &mut v]);
                [u[0], v[0]]
            }
            ReadMap::F32(m) => {
                let (mut u, mut v) = ([0f32], [0f32]);
                m.invert_soa(
                    [&[d[0] as f32], &[d[1] as f32], &[d[2] as f32]],
                    [&mut u, &mut v],
                );
                [f64::from(u[0]), f64::from(v[0])]
            }
        };
        if uv[0].is_finite() && uv[1].is_finite() {
            Ok(uv)
        } else {
            Err(crate::InvertError::OutsideDomain)
        }
    }
    fn target_pdf(&self, direction: crate::Vec3) -> f64 {
        let TargetTables::Grid(g) = &self.target else {
            return 0.0;
        };
        let Some(d) = unit(direction) else { return 0.0 };
        if self.layout == BlobLayout::Hemisphere && d[2] < 0.0 {
            return 0.0;
        }
        let total = g.integral();
        if !(total > 0.0 && total.is_finite()) {
            return 0.0;
        }
        let (t, p) = crate::sampler::spherical(d);
        g.interpolate(t, p) / total
    }
    fn memory_bytes(&self) -> usize {
        let map = match &self.map {
            ReadMap::F64(m) => m.memory_bytes(),
            ReadMap::F32(m) => m.memory_bytes(),
        };
        let target = match &self.target {
            TargetTables::None => 0,
            TargetTables::Grid(g) => 8 * (g.theta().len() + g.phi().len() + g.values().len()),
            TargetTables::Image { rgb, .. } => 4 * rgb.len(),
        };
        map + target + std::mem::size_of::<Self>()
    }
    /// The blob's precision runs its map's kernels (the writer's bits); the other precision is
    /// evaluated one point at a time through the scalar calls (which themselves run the blob's
    /// precision), each result rounded once.
    fn batch(&self, job: crate::batch::Batch<'_>) {
        use crate::batch::{Batch, Soa};
        match (job, &self.map) {
            (Batch::F64(Soa::Invert { dir, uv: [u, v] }), ReadMap::F64(m)) => {
                m.invert_soa(dir, [&mut *u, &mut *v]);
                let mut p = vec![0.0; u.len()];
                m.pdf_soa(dir, &mut p);
                for k in 0..u.len() {
                    if p[k] == 0.0 {
                        u[k] = f64::NAN;
                        v[k] = f64::NAN;
                    }
                }
            }
            (Batch::F64(job), ReadMap::F64(m)) => m.batch(job),
            (Batch::F32(job), ReadMap::F32(m)) => m.batch(job),
            (job, _) => crate::sampler::scalar_batch(self, job),
        }
    }
}
