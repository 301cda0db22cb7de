//! `gonio uv` and `gonio bake`: the inverse map as a texture parameterisation of a star-shaped
//! mesh (docs/TEXTURE.md).
//!
//! * `gonio uv MESH.obj|.ply -o OUT.obj [--density surface|solid-angle|property:NAME|FILE]
//!   [--center X,Y,Z] [--layout hds|latlong|cube|octahedral] [--grid N]`: writes the mesh with
//!   `vt` and prints the centre, the cut and the measures on standard error.
//! * `gonio bake MESH … --texture IMAGE.png|IMAGE.hdr|.exr|.pfm|checker --resolution N -o TEX.png
//!   [--obj OUT.obj] [--preview PREVIEW.png]`: resamples an equirectangular image (or a procedural checkerboard over
//!   directions) into the map's square texture; `--obj` also writes the OBJ with an MTL (beside
//!   it, same stem) naming TEX.png, `--preview` a render of the mesh with a texture-space
//!   checkerboard.
//!
//! Inputs are read only if they are regular files ([`crate::input::read_regular`]); outputs go
//! through [`crate::output::Output`] (never an input of the run, no temporary file left behind).

use crate::input::read_regular;
use crate::output::Output;
use anyhow::{bail, Context, Result};
use clap::Args;
use gonio::mesh::bake::{
    bake, checker_direction, checker_uv, render_preview, sample_equirect, Image,
};
use gonio::mesh::metrics::{measure, surface_target};
use gonio::mesh::param::{area3, default_grid};
use gonio::mesh::star::solid_angle;
use gonio::mesh::{obj, parameterise, Density, Layout, Mesh, UvOptions, UvResult};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Options shared by `uv` and `bake`.
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// The mesh: Wavefront OBJ (.obj) or PLY (.ply, ASCII or binary).
    pub mesh: PathBuf,
    /// Texel density per steradian: `surface` (uniform over the surface), `solid-angle`
    /// (uniform per steradian), `property:NAME` (a per-vertex PLY property as weight × surface),
    /// or a diagram file (.json, .ies, .ldt) of weights over directions × surface.
    #[arg(long, default_value = "surface")]
    pub density: String,
    /// The centre X,Y,Z (default: the volume centroid, else a searched point that sees every
    /// triangle).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub center: Option<String>,
    /// The layout: `hds` (the inverse map), or the compared `latlong`, `cube`, `octahedral`.
    #[arg(long, default_value = "hds")]
    pub layout: String,
    /// Parallels of the density diagram (meridians: 2(N − 1)); default from the triangle count.
    #[arg(long, value_name = "N")]
    pub grid: Option<usize>,
}

/// `gonio uv`.
#[derive(Debug, Args)]
pub struct UvArgs {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// The output OBJ.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `gonio bake`.
#[derive(Debug, Args)]
pub struct BakeArgs {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// An equirectangular image: PNG, or `.hdr`/`.exr`/`.pfm` (linear values, clamped to [0, 1]
    /// in the 8-bit output), in the environment maps' lat-long frame (top row +z, centre column
    /// +x, φ decreasing to the right); or `checker` for a checkerboard over directions.
    #[arg(long)]
    pub texture: String,
    /// The square texture's width and height in texels.
    #[arg(long, default_value_t = 1024)]
    pub resolution: usize,
    /// The baked texture (PNG).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the mesh with `vt` here, with an MTL of the same stem naming the texture.
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// Also write a preview render (PNG) of the mesh with a texture-space checkerboard.
    #[arg(long)]
    pub preview: Option<PathBuf>,
}

fn shown(p: &Path) -> String {
    p.display().to_string()
}

/// Reads the mesh (by extension, else by content) and prints the reader's warnings.
fn read_mesh(path: &Path) -> Result<Mesh> {
    let name = shown(path);
    let bytes = read_regular(path, &name, crate::input::FileKind::Mesh)?;
    let (mesh, warnings) =
        gonio::mesh::read_any(&bytes, Some(path)).with_context(|| name.clone())?;
    for w in warnings {
        eprintln!("gonio: warning: {name}: {w}");
    }
    if !mesh.texcoords.is_empty() {
        eprintln!(
            "gonio: warning: {name}: its {} texture coordinates are replaced by the parameterisation",
            mesh.texcoords.len()
        );
    }
    Ok(mesh)
}

fn parse_center(s: &str) -> Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| anyhow::anyhow!("--center: `{s}` is not three numbers X,Y,Z"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        _ => bail!("--center: `{s}` is not three finite numbers X,Y,Z"),
    }
}

fn parse_layout(s: &str) -> Result<Layout> {
    Ok(match s {
        "hds" => Layout::Hds,
        "latlong" => Layout::LatLong,
        "cube" => Layout::Cube,
        "octahedral" => Layout::Octahedral,
        _ => bail!("--layout: `{s}` is not one of hds, latlong, cube, octahedral"),
    })
}

fn options(a: &MeshArgs, mesh: &Mesh, settings: &crate::settings::Settings) -> Result<UvOptions> {
    let density = match a.density.as_str() {
        "surface" => Density::Surface,
        "solid-angle" => Density::SolidAngle,
        s if s.starts_with("property:") => {
            let name = &s["property:".len()..];
            match mesh.property(name) {
                Some(v) => Density::VertexWeight(v.to_vec()),
                None => bail!(
                    "--density: the mesh has no vertex property `{name}` (it has: {})",
                    mesh.vertex_properties
                        .iter()
                        .map(|p| p.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }
        }
        file => Density::Diagram(crate::load::load(file, settings)?.diagram),
    };
    let layout = parse_layout(&a.layout)?;
    if layout != Layout::Hds && a.density != "surface" {
        bail!(
            "--density applies to the hds layout only; the compared layouts have fixed densities"
        );
    }
    let grid = match a.grid {
        None => None,
        Some(n) if (3..=2001).contains(&n) => Some((n, 2 * (n - 1))),
        Some(n) => bail!("--grid: {n} parallels; give 3 to 2001"),
    };
    Ok(UvOptions {
        density,
        center: a.center.as_deref().map(parse_center).transpose()?,
        layout,
        grid,
        tolerance: settings.tolerance.or(Some(0.01)),
    })
}

/// Parameterises and prints the summary on standard error.
fn run_mesh(
    a: &MeshArgs,
    settings: &crate::settings::Settings,
) -> Result<(Mesh, UvOptions, UvResult)> {
    let mesh = read_mesh(&a.mesh)?;
    let opts = options(a, &mesh, settings)?;
    let t = std::time::Instant::now();
    let r = parameterise(&mesh, &opts).with_context(|| shown(&a.mesh))?;
    let secs = t.elapsed().as_secs_f64();
    let c = r.star.center;
    let center = r.star.center;
    let target = |src: u32, p: [[f64; 3]; 3]| -> f64 {
        match &opts.density {
            Density::Surface => surface_target(src, p),
            Density::SolidAngle => {
                let q = p.map(|x| [x[0] - center[0], x[1] - center[1], x[2] - center[2]]);
                solid_angle(q[0], q[1], q[2]).abs()
            }
            Density::VertexWeight(w) => {
                let t = mesh.triangles[src as usize];
                area3(p[0], p[1], p[2]) * (w[t[0] as usize] + w[t[1] as usize] + w[t[2] as usize])
                    / 3.0
            }
            Density::Diagram(d) => {
                let g = [
                    (p[0][0] + p[1][0] + p[2][0]) / 3.0 - center[0],
                    (p[0][1] + p[1][1] + p[2][1]) / 3.0 - center[1],
                    (p[0][2] + p[1][2] + p[2][2]) / 3.0 - center[2],
                ];
                let (th, ph) = gonio::sampler::spherical(g);
                area3(p[0], p[1], p[2]) * d.interpolate(th, ph)
            }
        }
    };
    let m = measure(&r.mesh, &target, opts.layout.native_aspect());
    let grid = opts
        .grid
        .unwrap_or_else(|| default_grid(mesh.triangles.len()));
    eprintln!(
        "gonio uv: {}: {} triangles, centre ({:.6}, {:.6}, {:.6}) ({}), layout {}{}; {} triangles cut along the seams, {} out; flipped {}, degenerate {}; texel/surface ratio to target: min {:.3}, max {:.3}, 1st–99th percentile {:.3}–{:.3}; L2 stretch {:.3}, L∞ {:.2}; seam length {:.4}; {:.3} s",
        shown(&a.mesh),
        mesh.triangles.len(),
        c[0],
        c[1],
        c[2],
        r.star.how,
        opts.layout.name(),
        if opts.layout == Layout::Hds {
            format!(", density grid {} × {}", grid.0, grid.1)
        } else {
            String::new()
        },
        r.cut_triangles,
        m.triangles,
        m.flipped,
        m.degenerate,
        m.ratio_range.0,
        m.ratio_range.1,
        m.ratio_p01_p99.0,
        m.ratio_p01_p99.1,
        m.l2,
        m.linf,
        m.seam_length,
        secs
    );
    Ok((mesh, opts, r))
}

fn write_text(path: &Path, text: &[u8]) -> Result<()> {
    let mut out = Output::create(Some(path))?;
    out.write_all(text)?;
    out.finish()
}

/// `gonio uv`.
pub fn run_uv(a: &UvArgs, settings: &crate::settings::Settings) -> Result<()> {
    let (_, _, r) = run_mesh(&a.mesh, settings)?;
    write_text(&a.output, obj::write_obj(&r.mesh, None).as_bytes())
}

/// Decodes a PNG to an RGB float image in [0, 1] (sRGB values as stored, not linearised).
fn read_png(path: &Path) -> Result<Image> {
    let name = shown(path);
    let bytes = read_regular(path, &name, crate::input::FileKind::Image)?;
    let mut dec = png::Decoder::new(std::io::Cursor::new(&bytes));
    dec.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = dec
        .read_info()
        .with_context(|| format!("{name}: not a PNG image"))?;
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .with_context(|| format!("{name}: cannot decode the PNG image"))?;
    let (w, h) = (info.width as usize, info.height as usize);
    let ch = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => bail!("{name}: indexed PNG left unexpanded"),
    };
    if w < 2 || h < 2 {
        bail!("{name}: the image is {w} × {h}; an equirectangular texture needs at least 2 × 2");
    }
    let rgb = buf[..w * h * ch]
        .chunks_exact(ch)
        .map(|p| {
            let f = |v: u8| v as f32 / 255.0;
            if ch < 3 {
                [f(p[0]); 3]
            } else {
                [f(p[0]), f(p[1]), f(p[2])]
            }
        })
        .collect();
    Ok(Image {
        width: w,
        height: h,
        rgb,
    })
}

/// Reads a high-dynamic-range lat-long image (`.hdr`, `.exr`, `.pfm`, by the readers of
/// `gonio::image`) as linear RGB floats, in the frame of the environment maps.
fn read_hdr_image(path: &Path) -> Result<Image> {
    let name = shown(path);
    let bytes = read_regular(path, &name, crate::input::FileKind::Image)?;
    let format = gonio::image::ImageFormat::sniff(&bytes)
        .or_else(|| gonio::image::ImageFormat::from_path(path));
    let img = gonio::image::Image::from_bytes(&bytes, format)
        .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    for w in img.warnings() {
        eprintln!("gonio: warning: {name}: {w}");
    }
    let (w, h) = (img.width(), img.height());
    if w < 2 || h < 2 {
        bail!("{name}: the image is {w} × {h}; an equirectangular texture needs at least 2 × 2");
    }
    let rgb = img
        .rgb()
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    Ok(Image {
        width: w,
        height: h,
        rgb,
    })
}

/// Encodes an RGB float image (clamped to [0, 1]) as an 8-bit RGB PNG.
fn encode_png(img: &Image) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, img.width as u32, img.height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let data: Vec<u8> = img
            .rgb
            .iter()
            .flat_map(|p| p.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
            .collect();
        enc.write_header()?.write_image_data(&data)?;
    }
    Ok(bytes)
}

/// `gonio bake`.
pub fn run_bake(a: &BakeArgs, settings: &crate::settings::Settings) -> Result<()> {
    if !(1..=16384).contains(&a.resolution) {
        bail!("--resolution: {} texels; give 1 to 16384", a.resolution);
    }
    if a.mesh.layout != "hds" {
        bail!("bake: only the hds layout has a texture map to bake into");
    }
    // Every output, checked against the others before any work (and against the inputs when it is
    // created, all of them before anything is written): -o, --obj and its MTL, --preview.
    let mtl = a.obj.as_ref().map(|o| o.with_extension("mtl"));
    let mut outputs: Vec<(&str, &Path)> = vec![("-o", a.output.as_path())];
    if let (Some(o), Some(m)) = (&a.obj, &mtl) {
        outputs.push(("--obj", o.as_path()));
        outputs.push(("the MTL beside --obj", m.as_path()));
    }
    if let Some(pv) = &a.preview {
        outputs.push(("--preview", pv.as_path()));
    }
    crate::output::check_distinct(&outputs)?;
    let source = if a.texture == "checker" {
        None
    } else if crate::envmap_in::is_image_name(&a.texture) {
        Some(read_hdr_image(Path::new(&a.texture))?)
    } else {
        Some(read_png(Path::new(&a.texture))?)
    };
    let (_, _, r) = run_mesh(&a.mesh, settings)?;
    let tex = r
        .texture
        .as_ref()
        .context("the hds layout has a texture map")?;
    let tex_name = a
        .output
        .file_name()
        .and_then(|s| s.to_str())
        .context("the texture's file name is not text")?;
    let mtl_name = match &mtl {
        Some(m) => Some(
            m.file_name()
                .and_then(|s| s.to_str())
                .context("the MTL's file name is not text")?,
        ),
        None => None,
    };
    // All the destinations (each refused here if it is an input), before anything is written:
    // a refusal leaves no output behind.
    let mut png_out = Output::create(Some(&a.output))?;
    let mut obj_out = match (&a.obj, &mtl) {
        (Some(o), Some(m)) => Some((Output::create(Some(o))?, Output::create(Some(m))?)),
        _ => None,
    };
    let mut preview_out = match &a.preview {
        Some(pv) => Some(Output::create(Some(pv))?),
        None => None,
    };
    let t = std::time::Instant::now();
    let img = match &source {
        Some(src) => bake(tex, a.resolution, &|d| sample_equirect(src, d)),
        None => bake(tex, a.resolution, &|d| checker_direction(d, 24)),
    };
    eprintln!(
        "gonio bake: {} × {} texels in {:.3} s",
        a.resolution,
        a.resolution,
        t.elapsed().as_secs_f64()
    );
    png_out.write_all(&encode_png(&img)?)?;
    if let (Some((o, m)), Some(mtl_name)) = (&mut obj_out, mtl_name) {
        o.write_all(obj::write_obj(&r.mesh, Some((mtl_name, tex_name))).as_bytes())?;
        m.write_all(obj::write_mtl(tex_name).as_bytes())?;
    }
    if let Some(out) = &mut preview_out {
        let seam = tex.seam();
        let img = render_preview(&r.mesh, 1024, &|uv| checker_uv(uv, 32, 16, seam));
        out.write_all(&encode_png(&img)?)?;
    }
    png_out.finish()?;
    if let Some((o, m)) = obj_out {
        o.finish()?;
        m.finish()?;
    }
    if let Some(out) = preview_out {
        out.finish()?;
    }
    Ok(())
}
