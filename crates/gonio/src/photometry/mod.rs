//! File → diagram: IES LM-63 and EULUMDAT readers, symmetry expansion, and writers.
//!
//! # The frame
//!
//! Every direction of a photometric file is expressed in the crate's frame (see [`crate::diagram`]):
//!
//! * vertical angle **γ = 0° (nadir) is −z**, γ = 180° (zenith) is +z, so the diagram's polar angle
//!   is **θ = 180° − γ**;
//! * horizontal angle **C = 0° lies along +x and C = 90° along +y**, so the diagram's azimuth is
//!   **φ = C**.
//!
//! Types B and A (IES photometric types 2 and 3) are brought into this frame as described in
//! [`Photometry::to_diagram`]: the aiming direction H = 0°, V = 0° is nadir (−z), H = +90° is +y and
//! (V = +90°, H = 0°) is +x.
//!
//! # What is kept exactly
//!
//! For type C files (and every EULUMDAT file) the diagram's nodes are the file's nodes and their
//! mirror images, and each node value is the file's value times [`Photometry::intensity_scale`]:
//! interpolation never smooths or shifts a measured value.
//!
//! # Robustness
//!
//! The readers never panic. Every error is a [`ParseError`] with the 1-based line and column (in
//! bytes, after a UTF-8 byte-order mark) of the offending token; problems of the file as a whole
//! have line 0. Counts are checked with overflow-safe arithmetic against [`MAX_ANGLES`],
//! [`crate::diagram::MAX_NODES`] and against the number of tokens actually present before anything
//! proportional to them is allocated. Everything that is tolerated but unusual is reported as a
//! [`Warning`]. See `docs/PHOTOMETRY.md` for the complete rules.

use crate::diagram::Diagram;
use std::fmt;
use std::path::{Path, PathBuf};

mod expand;
mod ies;
mod ldt;
mod tokens;
mod validate;
mod write;

pub use expand::direction_of_hv;
pub use write::{write_ies, write_ldt, WriteMeta};

/// Largest number of angles accepted on one axis (vertical or horizontal, or TILT angles).
pub const MAX_ANGLES: usize = 100_000;

/// Smallest step in degrees between consecutive angles of a file: closer angles are refused as
/// duplicates (so that every conversion keeps them distinct).
pub const MIN_ANGLE_STEP_DEG: f64 = 1e-9;

/// Largest number of header lines (keywords, `[MORE]` and free text) before the `TILT=` line of
/// an IES file: a file without a `TILT=` line within them is refused (real headers have a few
/// dozen lines; the cap bounds the memory and the warnings a hostile header can cost).
pub const MAX_HEADER_LINES: usize = 10_000;

/// Largest number of EULUMDAT lamp sets accepted.
pub const MAX_LAMP_SETS: usize = 1_000;

/// Resolution in degrees of the type C grid onto which type A and B files are resampled: the
/// polar angle θ (and γ) in steps of 0.5°.
pub const RESAMPLE_STEP_THETA_DEG: f64 = 0.5;

/// Resolution in degrees of the meridians (C planes) onto which type A and B files are resampled.
pub const RESAMPLE_STEP_PHI_DEG: f64 = 1.0;

/// A photometric file could not be read: what is wrong, and where (1-based line and column).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{line}:{column}: {message}")]
pub struct ParseError {
    /// 1-based line of the offending token (0 when the problem is the file as a whole).
    pub line: usize,
    /// 1-based column of the offending token (0 when unknown).
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl ParseError {
    pub(crate) fn new(line: usize, column: usize, message: impl Into<String>) -> Self {
        Self {
            line,
            column,
            message: message.into(),
        }
    }
}

/// Something unusual that the reader tolerated, and where (1-based line and column; 0 when it
/// concerns the file as a whole).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// 1-based line (0 for the file as a whole).
    pub line: usize,
    /// 1-based column (0 when unknown).
    pub column: usize,
    /// What was tolerated and how it was handled.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: warning: {}",
            self.line, self.column, self.message
        )
    }
}

/// The two photometric file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FileFormat {
    /// IES LM-63 (1986, 1991, 1995, 2002, 2019).
    Ies,
    /// EULUMDAT (`.ldt`).
    Eulumdat,
}

impl FileFormat {
    /// The format the content shows, if it shows one: IES when the first line starts with
    /// `IESNA` or `IES:` or a line among the first 200 starts with `TILT=`; EULUMDAT when lines 2
    /// and 3 are the integers Ityp (0–3) and Isym (0–4), line 4 an integer, and no `TILT=` line
    /// was seen. A UTF-8 byte-order mark is skipped; UTF-16 text and anything else give `None`.
    /// The CLI takes the file's extension as a hint and says so when the two disagree.
    pub fn detect(bytes: &[u8]) -> Option<Self> {
        if utf16_encoding(bytes).is_some() {
            return None;
        }
        let bytes = tokens::strip_bom(bytes);
        let head = &bytes[..bytes.len().min(1 << 16)];
        let text = String::from_utf8_lossy(head);
        let lines: Vec<&str> = text
            .split(['\n', '\r'])
            .filter(|l| !l.trim().is_empty())
            .take(200)
            .collect();
        let first = lines.first()?.trim_start().to_ascii_uppercase();
        if first.starts_with("IESNA") || first.starts_with("IES:") {
            return Some(Self::Ies);
        }
        if lines
            .iter()
            .any(|l| l.trim_start().to_ascii_uppercase().starts_with("TILT"))
        {
            return Some(Self::Ies);
        }
        // EULUMDAT is line-oriented: count raw lines (blank ones too) for lines 2–4.
        let raw: Vec<&str> = text.lines().take(4).collect();
        let int = |k: usize| raw.get(k).and_then(|l| l.trim().parse::<i64>().ok());
        match (int(1), int(2), int(3)) {
            (Some(t), Some(s), Some(_)) if (0..=3).contains(&t) && (0..=4).contains(&s) => {
                Some(Self::Eulumdat)
            }
            _ => None,
        }
    }

    /// The format named by a path's extension: `.ies` → [`FileFormat::Ies`], `.ldt` →
    /// [`FileFormat::Eulumdat`] (any letter case); `None` otherwise.
    pub fn from_path_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ies" => Some(Self::Ies),
            "ldt" => Some(Self::Eulumdat),
            _ => None,
        }
    }
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Ies => "IES LM-63",
            Self::Eulumdat => "EULUMDAT",
        })
    }
}

/// The version of the file format, as recognised from the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Version {
    /// LM-63-1986: no version line, free-text header.
    Ies1986,
    /// LM-63-1991: `IESNA91`.
    Ies1991,
    /// LM-63-1995: `IESNA:LM-63-1995` (also the non-standard `IESNA95`).
    Ies1995,
    /// LM-63-2002: `IESNA:LM-63-2002`.
    Ies2002,
    /// LM-63-2019: `IES:LM-63-2019`.
    Ies2019,
    /// EULUMDAT (the format has no version field).
    Eulumdat,
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Ies1986 => "LM-63-1986",
            Self::Ies1991 => "LM-63-1991",
            Self::Ies1995 => "LM-63-1995",
            Self::Ies2002 => "LM-63-2002",
            Self::Ies2019 => "LM-63-2019",
            Self::Eulumdat => "EULUMDAT",
        })
    }
}

/// The photometric type: how the angles of the file are laid out around the luminaire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhotometricType {
    /// Type C (IES type 1, every EULUMDAT file): vertical polar axis; γ from nadir, C planes about
    /// the vertical axis.
    C,
    /// Type B (IES type 2): the polar axis is the luminaire's lateral horizontal axis; V is the
    /// angle of the plane about that axis, H the angle within the plane.
    B,
    /// Type A (IES type 3): the polar axis is the luminaire's vertical axis seen from the front; H
    /// is the angle of the plane about that axis, V the elevation within the plane.
    A,
}

impl fmt::Display for PhotometricType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::C => "C",
            Self::B => "B",
            Self::A => "A",
        })
    }
}

/// The symmetry implied by the stored horizontal angles (IES) or the symmetry indicator Isym
/// (EULUMDAT), and so the rule that expands the stored planes to the whole sphere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Symmetry {
    /// One plane: the distribution is rotationally symmetric about the vertical axis
    /// (IES: one horizontal angle; EULUMDAT Isym 1).
    Rotational,
    /// Symmetric about the C0–C180 and the C90–C270 planes: C0–C90 is stored
    /// (IES 0–90; EULUMDAT Isym 4). The images of C are 180° − C, 180° + C and 360° − C.
    Quadrant,
    /// Symmetric about the C0–C180 plane: C0–C180 is stored (IES 0–180; EULUMDAT Isym 2). The
    /// image of C is 360° − C.
    BilateralC0C180,
    /// Symmetric about the C90–C270 plane: C90–C270 (IES 90–270) or C270 → C0 → C90 (EULUMDAT
    /// Isym 3) is stored. The image of C is 180° − C.
    BilateralC90C270,
    /// No symmetry: a full set of planes (IES: last angle above 180°, up to 360°; EULUMDAT Isym
    /// 0). A plane at C0 + 360° duplicates the first one and is dropped.
    None,
    /// Type A or B: what was mirrored to complete the H and V ranges. `horizontal`: H starts at
    /// 0°, so the image of H is −H; `vertical`: V starts at 0°, so the image of V is −V.
    TypeAB {
        /// H mirrored (H stored from 0°).
        horizontal: bool,
        /// V mirrored (V stored from 0°).
        vertical: bool,
    },
}

impl fmt::Display for Symmetry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Rotational => f.write_str("rotational (one plane)"),
            Self::Quadrant => f.write_str("quadrant (C0–C90 stored)"),
            Self::BilateralC0C180 => f.write_str("bilateral about the C0–C180 plane"),
            Self::BilateralC90C270 => f.write_str("bilateral about the C90–C270 plane"),
            Self::None => f.write_str("none (full set of planes)"),
            Self::TypeAB {
                horizontal,
                vertical,
            } => match (horizontal, vertical) {
                (false, false) => f.write_str("none (full H and V ranges)"),
                (true, false) => f.write_str("mirrored in H (H stored from 0°)"),
                (false, true) => f.write_str("mirrored in V (V stored from 0°)"),
                (true, true) => f.write_str("mirrored in H and V"),
            },
        }
    }
}

/// An IES TILT table: the factor by which the intensities change when the luminaire is tilted.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltTable {
    /// Lamp-to-luminaire geometry: 1 (lamp vertical), 2 (lamp horizontal, tilted in the C0–C180
    /// plane) or 3 (lamp horizontal, tilted in the C90–C270 plane).
    pub geometry: u8,
    /// Tilt angles in degrees, as in the file.
    pub angles_deg: Vec<f64>,
    /// Multiplying factors, one per angle (dimensionless).
    pub factors: Vec<f64>,
}

impl TiltTable {
    /// The factor at tilt angle `angle_deg` (degrees): linear interpolation in the table, the end
    /// values beyond its ends; 1 for an empty table.
    pub fn factor_at(&self, angle_deg: f64) -> f64 {
        let (a, f) = (&self.angles_deg, &self.factors);
        match a.len() {
            0 => 1.0,
            1 => f[0],
            n => {
                if angle_deg <= a[0] {
                    f[0]
                } else if angle_deg >= a[n - 1] {
                    f[n - 1]
                } else {
                    let k = crate::diagram::segment(a, angle_deg);
                    let t = (angle_deg - a[k]) / (a[k + 1] - a[k]);
                    f[k] + t * (f[k + 1] - f[k])
                }
            }
        }
    }
}

/// The TILT specification of an IES file.
#[derive(Debug, Clone, PartialEq)]
pub enum Tilt {
    /// `TILT=NONE` (also every EULUMDAT file).
    None,
    /// `TILT=INCLUDE`: the table follows in the file.
    Include(TiltTable),
    /// `TILT=<file>`: the table was read from the named file through the [`TiltResolver`].
    File {
        /// The file name as written after `TILT=`.
        name: String,
        /// The table read from it.
        table: TiltTable,
    },
}

impl Tilt {
    /// The table, if any.
    pub fn table(&self) -> Option<&TiltTable> {
        match self {
            Self::None => None,
            Self::Include(t) | Self::File { table: t, .. } => Some(t),
        }
    }
}

impl fmt::Display for Tilt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::None => f.write_str("NONE"),
            Self::Include(t) => write!(
                f,
                "INCLUDE (geometry {}, {} angles)",
                t.geometry,
                t.angles_deg.len()
            ),
            Self::File { name, table } => write!(
                f,
                "{name} (geometry {}, {} angles)",
                table.geometry,
                table.angles_deg.len()
            ),
        }
    }
}

/// Supplies the bytes of a file named by `TILT=<file>`. The library never opens a path by itself.
pub trait TiltResolver {
    /// The contents of the TILT file `name` (as written in the IES file), or a message saying why
    /// it cannot be had.
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String>;
}

/// A [`TiltResolver`] that refuses every name: use it when no TILT files are available.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoTiltFiles;

impl TiltResolver for NoTiltFiles {
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String> {
        Err(format!(
            "the file refers to the TILT file `{name}`, but no TILT files can be read here"
        ))
    }
}

/// Largest TILT file [`DirTiltResolver`] reads: 4 MiB (a table of [`MAX_ANGLES`] angle/factor
/// pairs fits in well under this). A larger file is refused before it is read.
pub const MAX_TILT_FILE_BYTES: u64 = 4 << 20;

/// A [`TiltResolver`] that reads TILT files from one directory chosen by the caller (the CLI uses
/// the directory of the IES file).
///
/// Only plain file names are accepted: a name with a path separator, a `..` component or a drive
/// prefix is refused. The name is then resolved with every symbolic link followed
/// ([`DirTiltResolver::locate`]): the result must be a regular file inside the directory (a link
/// that leaves it, a FIFO, a device or a directory is refused before the file is opened), of at most
/// [`MAX_TILT_FILE_BYTES`].
#[derive(Debug, Clone)]
pub struct DirTiltResolver {
    /// The directory the names are looked up in.
    pub dir: PathBuf,
}

impl DirTiltResolver {
    /// A resolver that looks names up in `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The canonical path (symbolic links resolved) of the TILT file `name`, after checking that
    /// `name` is a plain file name and that the path is a regular file inside [`Self::dir`] (also
    /// after canonicalisation). Nothing is opened.
    pub fn locate(&self, name: &str) -> Result<PathBuf, String> {
        let plain = !name.is_empty()
            && name != "."
            && name != ".."
            && !name.contains(['/', '\\', ':'])
            && !name.contains('\0');
        if !plain {
            return Err(format!(
                "TILT file name `{}` is not a plain file name; only files next to the IES file are read",
                tokens::excerpt(name.as_bytes())
            ));
        }
        let dir = std::fs::canonicalize(&self.dir)
            .map_err(|e| format!("cannot resolve the folder {}: {e}", self.dir.display()))?;
        let path = std::fs::canonicalize(self.dir.join(name)).map_err(|e| {
            format!(
                "cannot read TILT file {}: {e}",
                self.dir.join(name).display()
            )
        })?;
        if !path.starts_with(&dir) {
            return Err(format!(
                "TILT file {} leads outside the IES file's folder {} (through a symbolic link); refused",
                self.dir.join(name).display(),
                dir.display()
            ));
        }
        let meta = std::fs::metadata(&path)
            .map_err(|e| format!("cannot read TILT file {}: {e}", path.display()))?;
        if !meta.is_file() {
            return Err(format!(
                "TILT file {} is not a regular file; refused",
                path.display()
            ));
        }
        if meta.len() > MAX_TILT_FILE_BYTES {
            return Err(format!(
                "TILT file {} has {} bytes, more than the limit of {MAX_TILT_FILE_BYTES}; not read",
                path.display(),
                meta.len()
            ));
        }
        Ok(path)
    }
}

impl TiltResolver for DirTiltResolver {
    /// [`DirTiltResolver::locate`], then the one file reader ([`crate::input::file`]: a
    /// regular file, opened without blocking, at most the TILT limit).
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String> {
        let path = self.locate(name)?;
        crate::input::file::read_file(&path, crate::input::file::FileKind::Tilt)
            .map_err(|e| format!("TILT file {e}"))
    }
}

/// A keyword line of an IES file (`[KEY] value`, with `[MORE]` lines appended).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Keyword {
    /// The keyword without brackets, e.g. `MANUFAC` or `_LAMPLUMENS`.
    pub key: String,
    /// The value, trimmed; `[MORE]` continuations are appended after a newline.
    pub value: String,
    /// 1-based line of the keyword.
    pub line: usize,
}

/// One set of lamps.
#[derive(Debug, Clone, PartialEq)]
pub struct LampSet {
    /// Number of lamps. IES: the file's number of lamps. EULUMDAT: field 26a, negative for
    /// absolute photometry.
    pub count: i64,
    /// Lamp type or description (EULUMDAT 26b; IES: the `[LAMP]` keyword, or empty).
    pub description: String,
    /// Total luminous flux of the set in lumens (EULUMDAT 26c; IES: number of lamps × lumens per
    /// lamp, or −1 for absolute photometry).
    pub flux_lm: f64,
    /// Colour temperature or colour appearance (EULUMDAT 26d; empty for IES).
    pub color: String,
    /// Colour rendering group or index (EULUMDAT 26e; empty for IES).
    pub color_rendering: String,
    /// Wattage including ballast in watts (EULUMDAT 26f; IES input watts).
    pub watts: f64,
}

/// IES-specific fields of a [`Photometry`].
#[derive(Debug, Clone, PartialEq)]
pub struct IesInfo {
    /// The version line as written (empty for LM-63-1986).
    pub version_line: String,
    /// Number of lamps.
    pub lamps: i64,
    /// Lumens per lamp (−1: absolute photometry).
    pub lumens_per_lamp: f64,
    /// Candela multiplier.
    pub multiplier: f64,
    /// Units of the dimensions: 1 = feet, 2 = metres.
    pub units_type: i64,
    /// Width of the luminous opening (in `units_type` units).
    pub width: f64,
    /// Length of the luminous opening.
    pub length: f64,
    /// Height of the luminous opening.
    pub height: f64,
    /// Ballast factor.
    pub ballast_factor: f64,
    /// Second field of the ballast line: ballast-lamp photometric factor (1986–1995, applied to
    /// the intensities), "future use" (2002) or file generation type (2019) (not applied).
    pub second_ballast_field: f64,
    /// Input watts.
    pub input_watts: f64,
}

/// EULUMDAT-specific fields of a [`Photometry`] (field numbers of the format in brackets).
#[derive(Debug, Clone, PartialEq)]
pub struct LdtInfo {
    /// (1) Company identification / databank / version.
    pub company: String,
    /// (2) Type indicator Ityp (0–3).
    pub ityp: i64,
    /// (3) Symmetry indicator Isym (0–4).
    pub isym: i64,
    /// (4) Number of C planes Mc between 0° and 360°.
    pub mc: usize,
    /// (5) Distance between C planes in degrees (0 for non-equidistant).
    pub dc: f64,
    /// (6) Number of luminous intensities in each C plane Ng.
    pub ng: usize,
    /// (7) Distance between γ angles in degrees (0 for non-equidistant).
    pub dg: f64,
    /// (8) Measurement report number.
    pub report_number: String,
    /// (9) Luminaire name.
    pub luminaire_name: String,
    /// (10) Luminaire number.
    pub luminaire_number: String,
    /// (11) File name.
    pub file_name: String,
    /// (12) Date / user.
    pub date_user: String,
    /// (13–15) Length or diameter, width (0 for round), height of the luminaire in mm.
    pub luminaire_dimensions_mm: [f64; 3],
    /// (16–17) Length or diameter, width of the luminous area in mm.
    pub luminous_area_mm: [f64; 2],
    /// (18–21) Height of the luminous area at C0, C90, C180, C270 in mm.
    pub luminous_area_heights_mm: [f64; 4],
    /// (22) Downward flux fraction DFF in %.
    pub downward_flux_fraction_pct: f64,
    /// (23) Light output ratio of the luminaire LORL in %.
    pub light_output_ratio_pct: f64,
    /// (24) Conversion factor for luminous intensities CFLI.
    pub conversion_factor: f64,
    /// (25) Tilt of the luminaire during measurement in degrees.
    pub measurement_tilt_deg: f64,
    /// (27) Direct ratios for room indices k = 0.6, 0.8, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0.
    pub direct_ratios: [f64; 10],
    /// (28) All Mc C angles in degrees, as listed in the file.
    pub c_angles_deg: Vec<f64>,
}

/// A photometric file, read. Angles in degrees as in the file; intensities in candela.
///
/// The intensities of the stored planes are kept twice: [`Photometry::raw_values`] as written
/// (candela for IES, cd/klm for EULUMDAT) and [`Photometry::candela`] = raw × [`Photometry::intensity_scale`].
#[derive(Debug, Clone, PartialEq)]
pub struct Photometry {
    /// The file format.
    pub format: FileFormat,
    /// The version recognised.
    pub version: Version,
    /// The photometric type (always C for EULUMDAT).
    pub photometric_type: PhotometricType,
    /// Free-text lines of the header (LM-63-1986 header lines, stray non-keyword lines of later
    /// versions), without line endings, decoded lossily from UTF-8.
    pub header: Vec<String>,
    /// The keywords, in file order (IES only).
    pub keywords: Vec<Keyword>,
    /// Lamp sets (IES: exactly one).
    pub lamp_sets: Vec<LampSet>,
    /// The TILT specification.
    pub tilt: Tilt,
    /// The tilt angle in degrees at which the TILT factor was applied: always 0 (the luminaire
    /// mounted as photometered).
    pub tilt_angle_deg: f64,
    /// Stored vertical angles in degrees, strictly increasing (γ for type C, V for types A and B).
    pub vertical_angles_deg: Vec<f64>,
    /// Stored horizontal angles in degrees, in stored order (C for type C, H for types A and B).
    /// Strictly increasing, except EULUMDAT Isym 3, stored C270 → C0 → C90.
    pub horizontal_angles_deg: Vec<f64>,
    /// The values as written in the file, row-major per stored horizontal plane:
    /// `raw_values[h * vertical_angles_deg.len() + v]`. Candela for IES, cd/klm for EULUMDAT.
    /// Tiny negative round-off values (see `docs/PHOTOMETRY.md`) are already clamped to 0.
    pub raw_values: Vec<f64>,
    /// The single factor that turns `raw_values` into candela:
    ///
    /// * IES: candela multiplier × ballast factor × (ballast-lamp photometric factor for
    ///   LM-63-1986/1991/1995) × TILT factor at [`Photometry::tilt_angle_deg`] (1 without TILT);
    /// * EULUMDAT: (total flux of the **first** lamp set / 1000 lm) × conversion factor CFLI.
    pub intensity_scale: f64,
    /// `raw_values × intensity_scale`: luminous intensity in candela, same layout as `raw_values`.
    pub candela: Vec<f64>,
    /// The symmetry and so the expansion rule.
    pub symmetry: Symmetry,
    /// IES-specific fields (`None` for EULUMDAT).
    pub ies: Option<IesInfo>,
    /// EULUMDAT-specific fields (`None` for IES).
    pub ldt: Option<LdtInfo>,
    /// Everything unusual the reader tolerated.
    pub warnings: Vec<Warning>,
}

/// Reads a photometric file from its bytes. TILT files named by an IES file are obtained through
/// `tilt` (pass [`NoTiltFiles`] when none can be read).
///
/// Never panics; on failure the [`ParseError`] names the line and column of the offending token.
pub fn read(
    bytes: &[u8],
    format: FileFormat,
    tilt: &dyn TiltResolver,
) -> Result<Photometry, ParseError> {
    if let Some(what) = not_text(bytes) {
        return Err(ParseError::new(
            1,
            1,
            format!(
                "{what}; photometric files are ASCII (or UTF-8 / Latin-1): save it in one of \
                 those"
            ),
        ));
    }
    let mut p = match format {
        FileFormat::Ies => ies::read_ies(bytes, tilt),
        FileFormat::Eulumdat => ldt::read_ldt(bytes),
    }?;
    p.warnings = aggregate_warnings(std::mem::take(&mut p.warnings));
    Ok(p)
}

/// Merges warnings with the same message into the first one, whose message then says how many
/// more there were and where the last one was (`… (and 199999 more like it, the last at line
/// 200007)`), so that a file with 200,000 identical slips gives one warning, not 200,000.
pub fn aggregate_warnings(warnings: Vec<Warning>) -> Vec<Warning> {
    use std::collections::HashMap;
    let mut first: HashMap<String, usize> = HashMap::new();
    let mut out: Vec<(Warning, usize, usize)> = Vec::new();
    for w in warnings {
        match first.get(&w.message) {
            Some(&k) => {
                out[k].1 += 1;
                out[k].2 = w.line;
            }
            None => {
                first.insert(w.message.clone(), out.len());
                out.push((w, 0, 0));
            }
        }
    }
    out.into_iter()
        .map(|(mut w, more, last)| {
            if more > 0 {
                w.message = format!(
                    "{} (and {more} more like it, the last at line {last})",
                    w.message
                );
            }
            w
        })
        .collect()
}

/// The largest input file every front end (CLI, Python, C) reads: 64 MiB, checked against the
/// file's size before anything is read (issue 25: one cap for all). The largest real files of
/// the test corpus are under 0.5 MB.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Why the bytes are not single-byte text, as the start of a message ("the file is UTF-16 text
/// (UTF-16LE, byte-order mark FF FE)"): only NUL bytes, UTF-32 or UTF-16 (issue 25: the first
/// two were reported as UTF-16); None for anything else.
pub fn not_text(bytes: &[u8]) -> Option<String> {
    let head = &bytes[..bytes.len().min(64)];
    if !head.is_empty() && head.iter().all(|&b| b == 0) {
        return Some(format!(
            "the file is not text: its first {} bytes are all NUL (0x00)",
            head.len()
        ));
    }
    if let Some(which) = utf32_encoding(bytes) {
        return Some(format!("the file is UTF-32 text ({which})"));
    }
    utf16_encoding(bytes).map(|which| format!("the file is UTF-16 text ({which})"))
}

/// Which UTF-32 encoding the bytes are in: a UTF-32 byte-order mark, or (without one) three NUL
/// bytes in every group of four of the first line's worth of ASCII.
fn utf32_encoding(bytes: &[u8]) -> Option<&'static str> {
    match bytes {
        [0xff, 0xfe, 0, 0, ..] => Some("UTF-32LE, byte-order mark FF FE 00 00"),
        [0, 0, 0xfe, 0xff, ..] => Some("UTF-32BE, byte-order mark 00 00 FE FF"),
        _ => {
            let head = &bytes[..bytes.len().min(64) / 4 * 4];
            if head.len() < 8 || head.iter().all(|&b| b == 0) {
                return None;
            }
            let quads = || head.chunks_exact(4);
            if quads().all(|q| q[1] == 0 && q[2] == 0 && q[3] == 0) {
                return Some("UTF-32LE without byte-order mark");
            }
            if quads().all(|q| q[0] == 0 && q[1] == 0 && q[2] == 0) {
                return Some("UTF-32BE without byte-order mark");
            }
            None
        }
    }
}

/// Which UTF-16 encoding the bytes are in, if they are UTF-16 text: a UTF-16 byte-order mark, or (without
/// one) a NUL in every other byte of the first line's worth of ASCII. Use [`not_text`] to tell
/// UTF-16 from UTF-32 and from NUL bytes, which this also matches.
pub fn utf16_encoding(bytes: &[u8]) -> Option<&'static str> {
    match bytes {
        [0xff, 0xfe, ..] => Some("UTF-16LE, byte-order mark FF FE"),
        [0xfe, 0xff, ..] => Some("UTF-16BE, byte-order mark FE FF"),
        _ => {
            let head = &bytes[..bytes.len().min(64)];
            if head.len() >= 8 {
                let odd_nul = head.iter().skip(1).step_by(2).all(|&b| b == 0);
                let even_nul = head.iter().step_by(2).all(|&b| b == 0);
                if odd_nul {
                    return Some("UTF-16LE without byte-order mark");
                }
                if even_nul {
                    return Some("UTF-16BE without byte-order mark");
                }
            }
            None
        }
    }
}

impl Photometry {
    /// The distribution expanded to the whole sphere in the crate's frame, values in candela.
    ///
    /// * **Type C** (and EULUMDAT): θ = 180° − γ (ascending), φ = C. The stored planes and their
    ///   mirror images under [`Photometry::symmetry`] become the meridians, strictly increasing in
    ///   [0°, 360°); node values are copied, never interpolated. The θ range is the measured γ range
    ///   (ends within 1e-6° of 0°, 90°, 180° snapped there); nothing is added outside it (a range
    ///   other than 0–90°, 90–180°, 0–180° was warned about at reading time; the maps put no light
    ///   outside the measured range, docs/MAPPING.md "Completion").
    /// * **Types A and B**: resampled by bilinear interpolation in (H, V) onto a regular grid of
    ///   [`RESAMPLE_STEP_THETA_DEG`] × [`RESAMPLE_STEP_PHI_DEG`], covering θ ∈ [90°, 180°] when
    ///   every measured direction lies in the lower hemisphere, θ ∈ [0°, 180°] otherwise. Type B:
    ///   direction (H, V) = sin H·ŷ + cos H (sin V·x̂ − cos V·ẑ); type A: (H, V) = sin V·x̂ +
    ///   cos V (sin H·ŷ − cos H·ẑ). Directions outside the measured (H, V) ranges carry zero.
    ///
    /// Fails only when the diagram would be empty of power (every value 0) or too large.
    pub fn to_diagram(&self) -> Result<Diagram, crate::DiagramError> {
        expand::to_diagram(self)
    }

    /// Whether [`Photometry::to_diagram`] resamples the distribution (types A and B, onto the grid
    /// of [`RESAMPLE_STEP_THETA_DEG`] × [`RESAMPLE_STEP_PHI_DEG`]) instead of copying the measured
    /// nodes (type C and EULUMDAT).
    pub fn is_resampled(&self) -> bool {
        self.photometric_type != PhotometricType::C
    }

    /// The largest stored intensity in candela (the file's maximum times
    /// [`Photometry::intensity_scale`]).
    pub fn max_intensity_cd(&self) -> f64 {
        self.candela.iter().fold(0.0, |a, &b| a.max(b))
    }

    /// Total luminous flux in lumens: the closed-form integral over the sphere of the interpolated
    /// distribution ([`Diagram::integral`] of [`Photometry::to_diagram`]); 0 when every value is 0.
    pub fn flux_lm(&self) -> f64 {
        self.to_diagram().map(|d| d.integral()).unwrap_or(0.0)
    }

    /// Types A and B: the intensity in candela at horizontal angle `h_deg` and vertical angle
    /// `v_deg` (degrees), bilinear in (H, V) on the stored table completed by the mirror images of
    /// [`Photometry::symmetry`]; 0 outside the measured ranges and for type C. This is the function
    /// that [`Photometry::to_diagram`] resamples.
    pub fn intensity_hv(&self, h_deg: f64, v_deg: f64) -> f64 {
        if self.photometric_type == PhotometricType::C {
            return 0.0;
        }
        expand::ab_intensity(self, h_deg, v_deg)
    }

    /// The value of keyword `key` (without brackets, any letter case), if present.
    pub fn keyword(&self, key: &str) -> Option<&str> {
        self.keywords
            .iter()
            .find(|k| k.key.eq_ignore_ascii_case(key))
            .map(|k| k.value.as_str())
    }
}

#[cfg(test)]
mod tests;
