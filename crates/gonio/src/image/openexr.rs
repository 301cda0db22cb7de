//! OpenEXR reader, through the `exr` crate (pure Rust; every compression it knows, scanline and
//! tiled files, `f16`, `f32` and `u32` samples).
//!
//! The first layer without deep data is read at its largest resolution level. Its channels are
//! chosen by name, grouped by their prefix (the part before the last `.`, as in multi-layer files
//! such as `View Layer.Combined.R`): `R`, `G`, `B` of one group (the unprefixed channels first,
//! then the groups in file order), else `Y` of one group (greyscale, R = G = B), else the file is
//! refused with the list of its channels. R, G and B never come from different groups. Other channels (`A`, depth, …) are ignored with a warning. Rows run from the
//! top of the data window down, as OpenEXR's y axis does. The header is read first, and before any
//! pixel is decoded its data window is checked against [`super::max_pixels`] and every flat
//! layer's decoded size (all its channels: the decoder allocates them all) against
//! [`MAX_EXR_DECODED_BYTES`], so that a small file cannot make the decoder allocate gigabytes. A
//! panic inside the decoder is caught and returned as [`ImageError::Exr`] (the `exr` crate's B44
//! decoder overflows an integer subtraction on some blocks, a panic where overflow checks are on:
//! docs/FUZZING.md).

use super::{check_size, Image, ImageError};
use exr::image::read::image::ReadLayers;
use exr::image::read::layers::ReadChannels;
use exr::meta::MetaData;
use std::io::Cursor;

const FORMAT: &str = "OpenEXR";

/// The most bytes the decoder may produce for one layer, every channel at full resolution (it
/// allocates them all, and decompresses every channel of a block): 1 GiB. An RGBA float image of
/// [`super::max_pixels`] pixels is 512 MiB; a file of a few kilobytes can declare hundreds of
/// channels, which the decoder would allocate before reading a byte of pixel data. (Blocks need no
/// limit of their own: the decoder clips a tile to the data window.)
pub const MAX_EXR_DECODED_BYTES: usize = 1 << 30;

/// The decoded-bytes budget of one layer in force: [`MAX_EXR_DECODED_BYTES`], or 16 bytes (RGBA
/// `f32`) a pixel of [`super::max_pixels`] when that is more (2 GiB at the default limit, so that a
/// 16384 × 8192 RGBA float sky opens).
pub fn max_exr_decoded_bytes() -> usize {
    MAX_EXR_DECODED_BYTES.max(super::max_pixels().saturating_mul(16))
}

/// Refuses a layer whose decoded pixels would exceed [`max_exr_decoded_bytes`] (computed without
/// overflow), before anything is decoded.
fn check_decoded_bytes(header: &exr::meta::header::Header) -> Result<(), ImageError> {
    let (w, h) = (header.layer_size.0, header.layer_size.1);
    let per_pixel: usize = header
        .channels
        .list
        .iter()
        .map(|c| c.sample_type.bytes_per_sample())
        .fold(0usize, usize::saturating_add);
    let layer = w.saturating_mul(h).saturating_mul(per_pixel);
    let limit = max_exr_decoded_bytes();
    if layer > limit {
        return Err(ImageError::BadSize {
            format: FORMAT,
            width: w,
            height: h,
            message: format!(
                "its {} channels ({per_pixel} bytes per pixel) would decode to {layer} bytes, more than the limit of {limit}",
                header.channels.list.len()
            ),
        });
    }
    Ok(())
}

/// The part of a channel name after its last `.` (its layer prefix removed).
fn base_name(name: &str) -> &str {
    name.rsplit('.').next().unwrap_or(name)
}

/// The part of a channel name before its last `.` (empty without a prefix).
fn prefix(name: &str) -> &str {
    name.rsplit_once('.').map_or("", |(p, _)| p)
}

/// The channels read, as indices into `names`: R, G, B of one layer, else Y of one layer
/// (three times). The layers are the channel-name prefixes (`diffuse.R` is layer `diffuse`);
/// the unprefixed channels come first, then the layers in the order of their first channel.
/// R, G and B are never taken from different layers.
pub(crate) fn pick_channels(names: &[String]) -> Option<Vec<usize>> {
    let mut layers: Vec<&str> = Vec::new();
    if names.iter().any(|n| prefix(n).is_empty()) {
        layers.push("");
    }
    for n in names {
        let p = prefix(n);
        if !layers.contains(&p) {
            layers.push(p);
        }
    }
    let find = |layer: &str, want: &str| {
        names
            .iter()
            .position(|n| prefix(n) == layer && base_name(n) == want)
    };
    for l in &layers {
        if let (Some(r), Some(g), Some(b)) = (find(l, "R"), find(l, "G"), find(l, "B")) {
            return Some(vec![r, g, b]);
        }
    }
    layers
        .iter()
        .find_map(|l| find(l, "Y"))
        .map(|y| vec![y, y, y])
}

/// The chunk bookkeeping the decoder does not check (issue 40: an uncompressed file whose chunks
/// all said y = 0 was read with rows 1–2 black, in silence): every chunk of a flat layer must name
/// a block of that layer (a scanline block aligned on the data window, a tile inside its level),
/// no block may come twice, and every block the offset table announces must be present. Errors
/// name the chunk (its index in file order). Reads the compressed chunks once, one at a time.
fn check_chunks(bytes: &[u8]) -> Result<(), ImageError> {
    use exr::block::chunk::CompressedBlock;
    use exr::block::reader::ChunksReader;
    use std::collections::HashSet;
    let chunk_err = |index: usize, message: String| ImageError::Exr {
        message: format!("chunk {index}: {message}"),
    };
    let reader = exr::block::read(Cursor::new(bytes), false).map_err(|e| ImageError::Exr {
        message: format!("the header (from byte 0): {e}"),
    })?;
    let mut chunks = reader.all_chunks(false).map_err(|e| ImageError::Exr {
        message: format!("the chunk offset table: {e}"),
    })?;
    let headers = chunks.meta_data().headers.clone();
    let mut seen: HashSet<(usize, usize, usize, usize, usize)> = HashSet::new();
    let mut per_layer = vec![0usize; headers.len()];
    let mut index = 0usize;
    while let Some(chunk) = chunks.read_next_chunk() {
        let chunk = chunk.map_err(|e| chunk_err(index, e.to_string()))?;
        let layer = chunk.layer_index;
        let Some(h) = headers.get(layer) else {
            return Err(chunk_err(
                index,
                format!("it names layer {layer}, the file has {}", headers.len()),
            ));
        };
        let coords = match &chunk.compressed_block {
            CompressedBlock::ScanLine(b) => {
                let size = h.compression.scan_lines_per_block() as i64;
                let top = i64::from(h.own_attributes.layer_position.y());
                let y = i64::from(b.y_coordinate);
                let rows = h.layer_size.height() as i64;
                if y < top || y >= top + rows || (y - top) % size != 0 {
                    return Err(chunk_err(
                        index,
                        format!(
                            "its scanline block starts at y = {y}, which is not one of the blocks of {size} row(s) from y = {top} to {}",
                            top + rows - 1
                        ),
                    ));
                }
                h.get_block_data_indices(&chunk.compressed_block)
                    .map_err(|e| chunk_err(index, e.to_string()))?
            }
            CompressedBlock::Tile(t) => {
                h.get_absolute_block_pixel_coordinates(t.coordinates)
                    .map_err(|e| chunk_err(index, format!("its tile is outside the layer: {e}")))?;
                t.coordinates
            }
            // Deep data is not read (the flat layer is chosen before).
            _ => {
                index += 1;
                continue;
            }
        };
        let key = (
            layer,
            coords.level_index.x(),
            coords.level_index.y(),
            coords.tile_index.x(),
            coords.tile_index.y(),
        );
        if !seen.insert(key) {
            return Err(chunk_err(
                index,
                format!(
                    "block {:?} of level {:?} of layer {layer} comes a second time (each block must be stored exactly once)",
                    (key.3, key.4),
                    (key.1, key.2)
                ),
            ));
        }
        per_layer[layer] += 1;
        index += 1;
    }
    for (layer, h) in headers.iter().enumerate() {
        if !h.deep && per_layer[layer] != h.chunk_count {
            return Err(ImageError::Exr {
                message: format!(
                    "layer {layer} has {} distinct blocks after chunk {index}, its offset table announces {}",
                    per_layer[layer], h.chunk_count
                ),
            });
        }
    }
    Ok(())
}

/// Reads an OpenEXR image from the bytes of a `.exr` file.
///
/// # Errors
/// [`ImageError::Exr`] for what the decoder refuses, [`ImageError::BadSize`] for an empty or
/// too large data window, [`ImageError::Unsupported`] for a file with neither RGB nor Y channels
/// or with deep data only, [`ImageError::NonFinite`] for NaN or infinite values.
pub fn read_exr(bytes: &[u8]) -> Result<Image, ImageError> {
    let result = std::panic::catch_unwind(|| read_exr_inner(bytes));
    match result {
        Ok(r) => r,
        Err(_) => Err(ImageError::Exr {
            message: "the decoder failed on this file (it panicked)".into(),
        }),
    }
}

fn read_exr_inner(bytes: &[u8]) -> Result<Image, ImageError> {
    let meta =
        MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(|e| ImageError::Exr {
            message: format!("the header (from byte 0): {e}"),
        })?;
    let Some(header) = meta.headers.iter().find(|h| !h.deep) else {
        return Err(ImageError::Unsupported {
            format: FORMAT,
            message: "the file holds only deep data".into(),
        });
    };
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    check_size(FORMAT, width, height)?;
    // Every layer the decoder might touch, not only the one read.
    for h in meta.headers.iter().filter(|h| !h.deep) {
        check_decoded_bytes(h)?;
    }
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let picks: Vec<usize> = match pick_channels(&names) {
        Some(p) => p,
        None => {
            return Err(ImageError::Unsupported {
                format: FORMAT,
                message: format!(
                    "the first layer has neither R, G, B nor Y channels (it has {})",
                    names.join(", ")
                ),
            })
        }
    };
    check_chunks(bytes)?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| ImageError::Exr {
            message: format!(
                "decoding the pixels (the chunks are in order; a chunk's data is bad): {e}"
            ),
        })?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    if (w, h) != (width, height) {
        return Err(ImageError::Exr {
            message: format!("the layer read is {w} × {h}, its header said {width} × {height}"),
        });
    }
    let list = &layer.channel_data.list;
    // The decoder sorts channels by name; find ours again by their full names.
    let index_of = |k: usize| list.iter().position(|c| c.name.to_string() == names[k]);
    let mut chans = Vec::with_capacity(3);
    for &k in &picks {
        let Some(i) = index_of(k) else {
            return Err(ImageError::Exr {
                message: format!("channel {} was not decoded", names[k]),
            });
        };
        if list[i].sample_data.len() != w * h {
            return Err(ImageError::Exr {
                message: format!(
                    "channel {} has {} samples for {w} × {h} pixels (subsampled channels are not supported)",
                    names[k],
                    list[i].sample_data.len()
                ),
            });
        }
        chans.push(&list[i].sample_data);
    }
    let mut rgb = vec![0f32; w * h * 3];
    for (c, data) in chans.iter().enumerate() {
        for (p, v) in rgb.iter_mut().skip(c).step_by(3).enumerate() {
            *v = data.value_by_flat_index(p).to_f32();
        }
    }
    let mut warnings = Vec::new();
    let used: Vec<&String> = picks.iter().map(|&k| &names[k]).collect();
    let ignored: Vec<&str> = names
        .iter()
        .filter(|n| !used.contains(n))
        .map(String::as_str)
        .collect();
    if !ignored.is_empty() {
        warnings.push(format!("channels ignored: {}", ignored.join(", ")));
    }
    if meta.headers.len() > 1 {
        warnings.push(format!(
            "only the first of {} layers was read",
            meta.headers.len()
        ));
    }
    let img = Image::from_parts(w, h, rgb, warnings);
    img.check_finite(FORMAT)?;
    Ok(img)
}
