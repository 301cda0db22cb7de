//! A **family** of hemisphere maps over an incident grid in one blob (layout 3, `docs/TABLES.md`
//! "Families"): every incident slice of a tabulated BRDF on one shared outgoing grid, the
//! incident grid, and the BRDF table itself, so that a device or a Dr.Jit kernel blends the slices
//! as [`crate::mapping::BlendedMap`] does and evaluates the table's interpolant.
//!
//! The slices share their grid (meridians, parallels, and so the tables `phi`, `beta`, `x`,
//! `radius_guide`, `inv_dx`, stored once); their other tables are stacked slice after slice
//! (`r2` of slice s at s·(M + 1), `d` at s·M·N, …), so that one array per table serves every
//! slice. Each slice's scalars (1/(2T_s), κ_s, the edge) are one row of the table `family.slice`;
//! a slice without a map (no reflectance) has a zero row and zero tables.

use super::*;
use crate::HemisphereMap;

/// The header's `layout` value of a family blob.
pub const LAYOUT_FAMILY: u32 = 3;
/// The header's `target` value of a family's BRDF table.
pub const TARGET_BRDF: u32 = 3;
/// Offset of the family descriptor (the second slot's bytes, unused by a family).
const FAMILY_OFFSET: usize = SLOT_OFFSET + SLOT_BYTES;
/// Ids of the family's own tables.
const ID_SLICE: u32 = 64;
const ID_THETA_I: u32 = 65;
const ID_PHI_I: u32 = 66;
/// Ids of the BRDF table: θ_o nodes, φ_o nodes (Δφ for an isotropic table), values.
const ID_BRDF_THETA_O: u32 = 48;
const ID_BRDF_PHI_O: u32 = 49;
const ID_BRDF_VALUES: u32 = 50;
/// The map tables shared by every slice (the grid's), by index in [`MAP_TABLES`].
const SHARED: [usize; 5] = [0, 1, 5, 9, 10];
/// Floats per row of `family.slice`: 1/(2T_s), κ_s, edge_s, 0.
const SLICE_ROW: usize = 4;

/// The BRDF table a family blob carries (every grid in radians, f64 in every blob).
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfTable<'a> {
    /// Whether the table depends on the incident azimuth (then `phi_o` is absolute).
    pub anisotropic: bool,
    /// 1 or 3.
    pub channels: usize,
    /// Incident polar nodes (the family's slices are at these and `phi_i`).
    pub theta_i: &'a [f64],
    /// Incident azimuth nodes (`[0]` for an isotropic table).
    pub phi_i: &'a [f64],
    /// Outgoing polar nodes.
    pub theta_o: &'a [f64],
    /// Outgoing azimuth nodes (Δφ = φ_o − φ_i for an isotropic table).
    pub phi_o: &'a [f64],
    /// Values, channel-major: `values[((c·A + a)·B + b)·P + p]` (A incident nodes, B θ_o, P φ_o).
    pub values: &'a [f64],
}

/// A family blob read back ([`read_family`]).
#[derive(Debug, Clone)]
pub struct FamilyTables {
    /// The tables' precision.
    pub precision: Precision,
    /// The shared grid of the slices: (M meridians, N parallels).
    pub grid: (usize, usize),
    /// Each slice's map, `None` for a slice without one; index a·(number of φ_i) + b. Each
    /// samples bit for bit as the slice map that wrote it.
    pub slices: Vec<Option<ReadMap>>,
    /// Whether the BRDF is anisotropic.
    pub anisotropic: bool,
    /// 1 or 3.
    pub channels: usize,
    /// Incident polar nodes (radians).
    pub theta_i: Vec<f64>,
    /// Incident azimuth nodes (radians).
    pub phi_i: Vec<f64>,
    /// Outgoing polar nodes (radians).
    pub theta_o: Vec<f64>,
    /// Outgoing azimuth nodes (radians).
    pub phi_o: Vec<f64>,
    /// The BRDF values, in [`BrdfTable::values`]' order.
    pub values: Vec<f64>,
}

/// Whether map table k (of [`MAP_TABLES`]) has one part per slice (else the slices share it).
fn stacked(k: usize) -> bool {
    !SHARED.contains(&k)
}

fn tables_of<T: BlobFloat>(
    slices: &[Option<(Tables<T>, T)>],
    elem: u32,
) -> Result<(Slot, [f64; 3], Vec<Pending>), TablesError> {
    let first = slices.iter().flatten().next().ok_or_else(|| {
        TablesError::Target("a family needs at least one slice with a map".into())
    })?;
    let t0 = &first.0;
    let grid_err = |s: usize, what: &str| {
        TablesError::Target(format!(
            "slice {s} does not share the first slice's grid ({what})"
        ))
    };
    for (s, t) in slices.iter().enumerate() {
        if let Some((t, _)) = t {
            let (a, r, a0, r0) = (&t.angular, &t.radial, &t0.angular, &t0.radial);
            if a.m != a0.m || r.n != r0.n || r.radial_k != r0.radial_k {
                return Err(grid_err(s, "counts"));
            }
            if a.wedge_guide.len() != a0.wedge_guide.len() {
                return Err(grid_err(s, "wedge guide length"));
            }
            let same = |a: &[T], b: &[T]| {
                a.len() == b.len()
                    && a.iter()
                        .zip(b)
                        .all(|(x, y)| x.as_f64().to_bits() == y.as_f64().to_bits())
            };
            if !same(&a.phi, &a0.phi)
                || !same(&a.beta, &a0.beta)
                || !same(&r.x, &r0.x)
                || !same(&r.inv_dx, &r0.inv_dx)
                || r.radius_guide != r0.radius_guide
                || a.inv_uniform_beta.as_f64() != a0.inv_uniform_beta.as_f64()
                || a.guide_scale.as_f64() != a0.guide_scale.as_f64()
                || r.radius_scale.as_f64() != r0.radius_scale.as_f64()
            {
                return Err(grid_err(s, "meridians, parallels or guides"));
            }
        }
    }
    let slot = Slot {
        m: t0.angular.m as u64,
        n: t0.radial.n as u64,
        k: t0.radial.radial_k as u64,
        g: t0.angular.wedge_guide.len() as u64,
        rg: t0.radial.radius_guide.len() as u64,
    };
    let counts = map_counts(slot.m, slot.n, slot.k, slot.g, slot.rg);
    // Stack the per-slice tables (zero for a slice without a map).
    let mut p = Vec::with_capacity(12);
    for (k, (_, guide)) in MAP_TABLES.iter().enumerate() {
        let id = map_table_id(0, k);
        if !stacked(k) {
            let t = t0;
            p.push(match k {
                0 => floats(id, elem, &t.angular.phi),
                1 => floats(id, elem, &t.angular.beta),
                5 => floats(id, elem, &t.radial.x),
                9 => guides(id, &t.radial.radius_guide),
                _ => floats(id, elem, &t.radial.inv_dx),
            });
            continue;
        }
        let c = counts[k] as usize;
        if *guide {
            let mut v = Vec::with_capacity(c * slices.len());
            for s in slices {
                match s {
                    Some((t, _)) => v.extend_from_slice(if k == 4 {
                        &t.angular.wedge_guide
                    } else {
                        &t.radial.radial_guide
                    }),
                    None => v.resize(v.len() + c, 0),
                }
            }
            p.push(guides(id, &v));
        } else {
            let mut v: Vec<T> = Vec::with_capacity(c * slices.len());
            for s in slices {
                match s {
                    Some((t, _)) => v.extend_from_slice(match k {
                        2 => &t.angular.r2,
                        3 => &t.angular.cum,
                        6 => &t.radial.d,
                        7 => &t.radial.u,
                        _ => &t.radial.total,
                    }),
                    None => v.resize(v.len() + c, zero_of(t0)),
                }
            }
            p.push(floats(id, elem, &v));
        }
    }
    let mut rows: Vec<T> = Vec::with_capacity(SLICE_ROW * slices.len());
    for s in slices {
        match s {
            Some((t, inv_2t)) => {
                rows.extend([*inv_2t, t.angular.kappa, t.radial.edge, zero_of(t0)])
            }
            None => rows.resize(rows.len() + SLICE_ROW, zero_of(t0)),
        }
    }
    p.push(floats(ID_SLICE, elem, &rows));
    let scalars = [
        t0.angular.inv_uniform_beta.as_f64(),
        t0.angular.guide_scale.as_f64(),
        t0.radial.radius_scale.as_f64(),
    ];
    Ok((slot, scalars, p))
}

/// The zero of the tables' element type (read from a table known to start at 0: Γ_0).
fn zero_of<T: BlobFloat>(t: &Tables<T>) -> T {
    t.angular.cum[0]
}

/// The family blob of `slices` (one per incident node, a·(number of φ_i) + b; `None` for a slice
/// without reflectance) in `precision`, with the BRDF `table` they were built from.
///
/// # Errors
/// [`TablesError::Target`] when no slice has a map, the slices do not share one grid, the
/// slice count is not that of the table's incident grid, or the table's sizes disagree;
/// [`TablesError::Float32`] for a grid beyond the float32 kernels' limits.
pub fn write_family(
    slices: &[Option<&HemisphereMap>],
    precision: Precision,
    table: &BrdfTable<'_>,
) -> Result<Vec<u8>, TablesError> {
    let (a, b) = (table.theta_i.len(), table.phi_i.len());
    let (no, po) = (table.theta_o.len(), table.phi_o.len());
    let expected = [a, b, no, po]
        .iter()
        .try_fold(table.channels, |x, &y| x.checked_mul(y));
    if slices.len() != a * b
        || !(table.channels == 1 || table.channels == 3)
        || expected != Some(table.values.len())
        || [a, b, no, po]
            .iter()
            .any(|&c| c == 0 || c > u32::MAX as usize)
    {
        return Err(TablesError::Target(format!(
            "a family of {} slices for a {} × {a} × {b} × {no} × {po} table with {} values",
            slices.len(),
            table.channels,
            table.values.len()
        )));
    }
    let mut header = vec![0u8; HEADER_BYTES];
    header[..8].copy_from_slice(&MAGIC);
    put_u32(&mut header, 8, VERSION);
    put_u32(&mut header, 12, HEADER_BYTES as u32);
    put_u32(&mut header, 32, precision.bytes() as u32);
    put_u32(&mut header, 36, LAYOUT_FAMILY);
    put_u32(&mut header, 40, Frame::Generic as u32);
    put_u32(&mut header, 44, TARGET_BRDF);
    put_u32(&mut header, 56, 1);
    // A blend's total is 1: its pdf is half its blended disk density.
    put_f64(&mut header, 72, 0.5);
    let (slot, [inv_ub, guide_scale, radius_scale], mut tables) = match precision {
        Precision::F32 => {
            let mut v = Vec::with_capacity(slices.len());
            for m in slices {
                v.push(match m {
                    Some(m) => {
                        let f = m.float32_map()?;
                        let inv = f.maps.inv_2t;
                        match f.maps.layout {
                            Layout::Hemisphere(t) => Some((t, inv)),
                            _ => unreachable!("a hemisphere map's float32 map is one hemisphere"),
                        }
                    }
                    None => None,
                });
            }
            tables_of(&v, ELEM_F32)?
        }
        Precision::F64 => {
            let v: Vec<_> = slices
                .iter()
                .map(|m| {
                    m.map(|m| {
                        let f = m.float64_map();
                        let inv = f.maps.inv_2t;
                        match f.maps.layout {
                            Layout::Hemisphere(t) => (t, inv),
                            _ => unreachable!("a hemisphere map's float64 map is one hemisphere"),
                        }
                    })
                })
                .collect();
            tables_of(&v, ELEM_F64)?
        }
    };
    // The shared grid's descriptor in slot 0 (κ and the edge are each slice's own).
    let mut d = [0u8; SLOT_BYTES];
    put_u32(&mut d, 0, slot.m as u32);
    put_u32(&mut d, 4, slot.n as u32);
    put_u32(&mut d, 8, slot.k as u32);
    put_u32(&mut d, 12, slot.g as u32);
    put_u32(&mut d, 16, slot.rg as u32);
    put_f64(&mut d, 32, inv_ub);
    put_f64(&mut d, 48, guide_scale);
    put_f64(&mut d, 56, radius_scale);
    header[SLOT_OFFSET..SLOT_OFFSET + SLOT_BYTES].copy_from_slice(&d);
    // The family descriptor.
    let f = FAMILY_OFFSET;
    put_u32(&mut header, f, a as u32);
    put_u32(&mut header, f + 4, b as u32);
    put_u32(&mut header, f + 8, u32::from(table.anisotropic));
    put_u32(&mut header, f + 12, table.channels as u32);
    put_u32(&mut header, f + 16, no as u32);
    put_u32(&mut header, f + 20, po as u32);
    tables.push(floats(ID_THETA_I, ELEM_F64, table.theta_i));
    tables.push(floats(ID_PHI_I, ELEM_F64, table.phi_i));
    tables.push(floats(ID_BRDF_THETA_O, ELEM_F64, table.theta_o));
    tables.push(floats(ID_BRDF_PHI_O, ELEM_F64, table.phi_o));
    tables.push(floats(ID_BRDF_VALUES, ELEM_F64, table.values));
    Ok(assemble(header, tables))
}

/// Strictly increasing angles in [0, `max`] (`max_open`: [0, max)).
fn angles(v: &[f64], name: &str, max: f64, max_open: bool) -> Result<(), TablesError> {
    for (k, &x) in v.iter().enumerate() {
        let inside = x >= 0.0 && if max_open { x < max } else { x <= max };
        if !inside {
            return Err(content(name, k, format!("{x} is outside its range")));
        }
        if k > 0 && !(x > v[k - 1]) {
            return Err(content(name, k, "does not increase strictly"));
        }
    }
    Ok(())
}

/// Validates `bytes` as a family blob (layout 3) and reads it back: the header checks of
/// [`read`], the family descriptor, the directory, every present slice's tables as [`read`]
/// checks one map's, zero rows and tables for the slices without a map, and the BRDF table
/// (finite values ≥ 0, angle grids strictly increasing in range).
///
/// # Errors
/// A [`TablesError`] naming the field, directory entry or table entry at fault.
pub fn read_family(bytes: &[u8]) -> Result<FamilyTables, TablesError> {
    let precision = check_header(bytes)?;
    let layout = u32_at(bytes, 36);
    if layout != LAYOUT_FAMILY {
        return Err(field(
            "layout",
            36,
            layout,
            "a family blob has layout 3 (read the others with blob::read)",
        ));
    }
    expect_u32(
        bytes,
        "frame",
        40,
        Frame::Generic as u32,
        "a family's frame is 0 (the local shading frame)",
    )?;
    expect_u32(
        bytes,
        "target",
        44,
        TARGET_BRDF,
        "a family carries its BRDF table (3)",
    )?;
    let table_count = u64::from(u32_at(bytes, 48));
    for (at, name) in [
        (52, "reserved"),
        (60, "lookup"),
        (88, "target_a"),
        (92, "target_b"),
    ] {
        expect_u32(bytes, name, at, 0, "must be 0 in a family")?;
    }
    expect_u32(
        bytes,
        "maps_present",
        56,
        1,
        "must be 1 (slot 0: the slices' grid)",
    )?;
    for (at, name, want) in [
        (64, "p_lower", 0.0),
        (72, "inv_2t", 0.5),
        (80, "target_integral", 0.0),
    ] {
        let v = f64_at(bytes, at);
        if v != want || v.is_sign_negative() {
            return Err(field(
                name,
                at,
                v,
                "p_lower 0, inv_2t 0.5, target_integral 0 in a family",
            ));
        }
    }
    let f32_limits = precision == Precision::F32;
    let slot = read_slot(bytes, 0, f32_limits)?;
    let f = FAMILY_OFFSET;
    let a = u64::from(u32_at(bytes, f));
    let b = u64::from(u32_at(bytes, f + 4));
    let aniso = u32_at(bytes, f + 8);
    let channels = u64::from(u32_at(bytes, f + 12));
    let no = u64::from(u32_at(bytes, f + 16));
    let po = u64::from(u32_at(bytes, f + 20));
    for (k, v) in [a, b, no, po].into_iter().enumerate() {
        if v == 0 {
            return Err(field(
                "family counts",
                f + 4 * if k < 2 { k } else { k + 2 },
                v,
                "every grid needs at least one node",
            ));
        }
    }
    if aniso > 1 {
        return Err(field(
            "family.symmetry",
            f + 8,
            aniso,
            "must be 0 (isotropic) or 1 (anisotropic)",
        ));
    }
    if aniso == 0 && b != 1 {
        return Err(field(
            "family.phi_i count",
            f + 4,
            b,
            "an isotropic table has one incident azimuth",
        ));
    }
    if channels != 1 && channels != 3 {
        return Err(field("family.channels", f + 12, channels, "must be 1 or 3"));
    }
    if let Some(r) = bytes[f + 24..HEADER_BYTES].iter().position(|&x| x != 0) {
        return Err(field(
            "family.reserved",
            f + 24 + r,
            bytes[f + 24 + r],
            "reserved bytes must be 0",
        ));
    }
    // Counts from the header, checked against the bytes present before anything is allocated
    // (the directory's offsets and counts are checked against the blob's length by `place`).
    let s = a * b;
    let counts = map_counts(slot.m, slot.n, slot.k, slot.g, slot.rg);
    let elem = match precision {
        Precision::F32 => ELEM_F32,
        Precision::F64 => ELEM_F64,
    };
    let too_many = |what: &str| {
        field(
            "family counts",
            f,
            what.to_string(),
            "more entries than the blob holds",
        )
    };
    let mut expect: Vec<Expect> = Vec::new();
    for (k, (name, guide)) in MAP_TABLES.iter().enumerate() {
        let count = if stacked(k) {
            counts[k].checked_mul(s).ok_or_else(|| too_many(name))?
        } else {
            counts[k]
        };
        expect.push(Expect {
            id: map_table_id(0, k),
            name: format!("family.{name}"),
            elem: if *guide { ELEM_U32 } else { elem },
            count,
        });
    }
    let values = [channels, a, b, no, po]
        .iter()
        .try_fold(1u64, |x, &y| x.checked_mul(y))
        .ok_or_else(|| too_many("values"))?;
    for (id, name, elem, count) in [
        (ID_SLICE, "family.slice", elem, s * SLICE_ROW as u64),
        (ID_THETA_I, "family.theta_i", ELEM_F64, a),
        (ID_PHI_I, "family.phi_i", ELEM_F64, b),
        (ID_BRDF_THETA_O, "brdf.theta_o", ELEM_F64, no),
        (ID_BRDF_PHI_O, "brdf.phi_o", ELEM_F64, po),
        (ID_BRDF_VALUES, "brdf.values", ELEM_F64, values),
    ] {
        expect.push(Expect {
            id,
            name: name.into(),
            elem,
            count,
        });
    }
    let placed = place(bytes, &expect, table_count)?;
    let g = |k: usize, name: &str| read_floats::<f64>(&placed[k], name);
    let theta_i = g(13, "family.theta_i")?;
    let phi_i = g(14, "family.phi_i")?;
    let theta_o = g(15, "brdf.theta_o")?;
    let phi_o = g(16, "brdf.phi_o")?;
    let vals = g(17, "brdf.values")?;
    use std::f64::consts::{FRAC_PI_2, TAU};
    let half = FRAC_PI_2 * (1.0 + 1e-12);
    angles(&theta_i, "family.theta_i", half, false)?;
    angles(&phi_i, "family.phi_i", TAU, true)?;
    angles(&theta_o, "brdf.theta_o", half, false)?;
    angles(&phi_o, "brdf.phi_o", TAU, true)?;
    if aniso == 0 && phi_i != [0.0] {
        return Err(content(
            "family.phi_i",
            0,
            "an isotropic table's incident azimuth is 0",
        ));
    }
    non_negative(&vals, "brdf.values")?;
    let slices = match precision {
        Precision::F32 => read_slices::<f32>(bytes, &slot, &placed, s as usize)?,
        Precision::F64 => read_slices::<f64>(bytes, &slot, &placed, s as usize)?,
    };
    Ok(FamilyTables {
        precision,
        grid: (slot.m as usize, slot.n as usize),
        slices,
        anisotropic: aniso == 1,
        channels: channels as usize,
        theta_i,
        phi_i,
        theta_o,
        phi_o,
        values: vals,
    })
}

/// Each slice's tables: its own part of every stacked table and the shared ones, checked as one
/// map's (a slice without a map: a zero row and zero tables).
#[allow(clippy::type_complexity)]
fn read_slices<T: ReadFloat>(
    bytes: &[u8],
    slot: &Slot,
    placed: &[Placed<'_>],
    s: usize,
) -> Result<Vec<Option<ReadMap>>, TablesError>
where
    Maps<T>: Into<ReadMap>,
{
    let rows = read_floats::<T>(&placed[12], "family.slice")?;
    let counts = map_counts(slot.m, slot.n, slot.k, slot.g, slot.rg);
    let mut out = Vec::with_capacity(s);
    for k in 0..s {
        let row = &rows[SLICE_ROW * k..SLICE_ROW * (k + 1)];
        let name = format!("slice {k} of family.slice");
        let part = |t: usize| -> Placed<'_> {
            if stacked(t) {
                let size = if MAP_TABLES[t].1 { 4 } else { T::SIZE };
                let c = counts[t] as usize * size;
                Placed {
                    bytes: &placed[t].bytes[k * c..(k + 1) * c],
                }
            } else {
                Placed {
                    bytes: placed[t].bytes,
                }
            }
        };
        if row.iter().all(|x| x.as_f64() == 0.0) {
            for t in (0..12).filter(|&t| stacked(t)) {
                if let Some(at) = part(t).bytes.iter().position(|&x| x != 0) {
                    return Err(content(
                        &format!("family.{}", MAP_TABLES[t].0),
                        k,
                        format!("slice {k} has no map, yet byte {at} of its part is not 0"),
                    ));
                }
            }
            out.push(None);
            continue;
        }
        let inv_2t = row[0];
        let kappa = row[1];
        let edge = row[2];
        if !(inv_2t.as_f64() > 0.0) {
            return Err(content(&name, SLICE_ROW * k, "1/(2T) must be > 0"));
        }
        if !(0.5..=2.0).contains(&kappa.as_f64()) {
            return Err(content(
                &name,
                SLICE_ROW * k + 1,
                "κ must be 1 up to round-off",
            ));
        }
        if edge.as_f64() < 0.0 {
            return Err(content(&name, SLICE_ROW * k + 2, "the edge must be ≥ 0"));
        }
        if row[3].as_f64() != 0.0 {
            return Err(content(&name, SLICE_ROW * k + 3, "reserved, must be 0"));
        }
        let sc = read_scalars::<T>(bytes, 0, true)?;
        let sc = Scalars { kappa, edge, ..sc };
        let parts: Vec<Placed<'_>> = (0..12).map(part).collect();
        let t = read_tables::<T>(
            &format!("family.slice{k}."),
            slot,
            sc,
            &parts,
            1.0,
            inv_2t.as_f64(),
        )?;
        out.push(Some(Maps::hemisphere(t, inv_2t).into()));
    }
    Ok(out)
}
