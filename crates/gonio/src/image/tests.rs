//! Readers and writers on generated images: every orientation and encoding, and the errors.

use super::*;

/// An image whose values RGBE represents exactly (small integers times powers of two).
fn exact_image(w: usize, h: usize) -> Image {
    let mut rgb = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            rgb.push((128 + (x * 7 + y) % 128) as f32 / 64.0);
            rgb.push((64 + (x + 3 * y) % 64) as f32 / 64.0);
            rgb.push(if (x + y) % 5 == 0 { 0.0 } else { 2.0 });
        }
    }
    Image::new(w, h, rgb).unwrap()
}

fn header(res: &str) -> Vec<u8> {
    format!("#?RADIANCE\n# comment\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1\n\n{res}\n").into_bytes()
}

#[test]
fn rgbe_conversion_is_exact_for_representable_values() {
    for v in [1.0f32, 0.5, 3.0, 1e-3, 1234.5, 255.0 / 64.0] {
        let e = write::f32_to_rgbe([v, v / 2.0, 0.0]);
        let back = hdr::rgbe_to_f32(e);
        assert!(
            back[0] <= v && back[0] >= v * (1.0 - 1.0 / 128.0),
            "{v} → {back:?}"
        );
    }
    assert_eq!(hdr::rgbe_to_f32([128, 64, 0, 129]), [1.0, 0.5, 0.0]);
    assert_eq!(hdr::rgbe_to_f32([200, 1, 1, 0]), [0.0; 3]);
}

#[test]
fn hdr_round_trips_run_length_and_flat() {
    for (w, h) in [(37, 5), (8, 3), (7, 4), (300, 2), (1, 1)] {
        let img = exact_image(w, h);
        for bytes in [write_hdr(&img), write_hdr_flat(&img)] {
            let back = read_hdr(&bytes).unwrap();
            assert_eq!((back.width(), back.height()), (w, h));
            assert_eq!(back.rgb(), img.rgb(), "{w}×{h}");
            assert!(back.warnings().is_empty());
        }
    }
    // Run-length coding is actually used (and shorter) for a constant image.
    let c = Image::constant(64, 4, [1.0, 1.0, 1.0]).unwrap();
    assert!(write_hdr(&c).len() < write_hdr_flat(&c).len() / 4);
    assert_eq!(read_hdr(&write_hdr(&c)).unwrap(), c);
}

#[test]
fn hdr_reads_every_orientation() {
    // A 3 × 2 image with pixel (x, y) = x + 3y + 1 (in the red channel, exponent 136 → value = byte).
    let (w, h) = (3usize, 2usize);
    let value = |x: usize, y: usize| (x + 3 * y + 1) as u8;
    for res in [
        "-Y 2 +X 3",
        "+Y 2 +X 3",
        "-Y 2 -X 3",
        "+Y 2 -X 3",
        "+X 3 -Y 2",
        "+X 3 +Y 2",
        "-X 3 -Y 2",
        "-X 3 +Y 2",
    ] {
        let t: Vec<&str> = res.split(' ').collect();
        let x_first = t[0].ends_with('X');
        let (slow_plus, fast_plus) = (t[0].starts_with('+'), t[2].starts_with('+'));
        let mut bytes = header(res);
        let (ns, nf) = if x_first { (w, h) } else { (h, w) };
        for s in 0..ns {
            for k in 0..nf {
                // Where file pixel (s, k) lies: X '+' left→right, Y '-' top→bottom.
                let along = |is_x: bool, plus: bool, i: usize, n: usize| {
                    if is_x == plus {
                        i
                    } else {
                        n - 1 - i
                    }
                };
                let (x, y) = if x_first {
                    (along(true, slow_plus, s, w), along(false, fast_plus, k, h))
                } else {
                    (along(true, fast_plus, k, w), along(false, slow_plus, s, h))
                };
                bytes.extend_from_slice(&[value(x, y), 0, 0, 136]);
            }
        }
        let img = read_hdr(&bytes).unwrap();
        assert_eq!((img.width(), img.height()), (w, h), "{res}");
        for y in 0..h {
            for x in 0..w {
                assert_eq!(
                    img.pixel(x, y)[0],
                    f32::from(value(x, y)),
                    "{res} at ({x}, {y})"
                );
            }
        }
    }
    // The standard orientation, spelled out: the first pixel of the file is the top left.
    let mut b = header("-Y 2 +X 3");
    for k in 0..6u8 {
        b.extend_from_slice(&[k + 1, 0, 0, 136]);
    }
    let img = read_hdr(&b).unwrap();
    assert_eq!(img.pixel(0, 0)[0], 1.0);
    assert_eq!(img.pixel(2, 1)[0], 6.0);
    // "+Y": the first scanline is the bottom row.
    let mut b = header("+Y 2 +X 3");
    for k in 0..6u8 {
        b.extend_from_slice(&[k + 1, 0, 0, 136]);
    }
    assert_eq!(read_hdr(&b).unwrap().pixel(0, 1)[0], 1.0);
}

#[test]
fn hdr_old_style_run_length() {
    // One pixel then a repeat of 5 then a repeat of 1·256 (consecutive codes shift by 8 bits).
    let mut b = header("-Y 1 +X 262");
    b.extend_from_slice(&[10, 20, 30, 136]);
    b.extend_from_slice(&[1, 1, 1, 5]);
    b.extend_from_slice(&[1, 1, 1, 1]);
    let img = read_hdr(&b).unwrap();
    assert_eq!(img.width(), 262);
    assert!((0..262).all(|x| img.pixel(x, 0) == [10.0, 20.0, 30.0]));
    // A repeat with nothing before it is an error with its offset.
    let mut b = header("-Y 1 +X 4");
    let at = b.len();
    b.extend_from_slice(&[1, 1, 1, 2]);
    match read_hdr(&b) {
        Err(ImageError::Scanline { row: 0, offset, .. }) => assert_eq!(offset, at),
        other => panic!("{other:?}"),
    }
}

#[test]
fn hdr_errors_are_typed_and_located() {
    let err = |b: &[u8]| read_hdr(b).unwrap_err();
    assert!(matches!(err(b"P6\n"), ImageError::Header { line: 1, .. }));
    assert!(matches!(
        err(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n"),
        ImageError::Header { line: 3, .. }
    ));
    assert!(matches!(
        err(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\0\0\0\0"),
        ImageError::Unsupported { .. }
    ));
    assert!(matches!(
        err(&header("-Y 2 -Y 3")),
        ImageError::Header { line: 6, .. }
    ));
    assert!(matches!(
        err(&header("-Y 0 +X 3")),
        ImageError::Header { .. }
    ));
    assert!(matches!(err(&header("Y 2 X 3")), ImageError::Header { .. }));
    // The column points at the token at fault (issue 40: line and column for text).
    assert!(matches!(
        err(&header("-Y 4 +X abc")),
        ImageError::Header {
            line: 6,
            column: 9,
            ..
        }
    ));
    assert!(matches!(
        err(&header("-Y 2 -Y 3")),
        ImageError::Header { column: 6, .. }
    ));
    let e = err(&header("-Y 4 +X abc")).to_string();
    assert!(e.contains("line 6, column 9"), "{e}");
    // Huge sizes are refused before allocation: by the limit, or by the bytes present.
    assert!(matches!(
        err(&header("-Y 60000 +X 60000")),
        ImageError::BadSize { .. }
    ));
    match err(&header("-Y 4000 +X 8000")) {
        ImageError::Truncated {
            needed, present, ..
        } => assert!(needed > present),
        other => panic!("{other:?}"),
    }
    // Run-length errors: a run past the end, a zero literal, a wrong length, a cut file.
    let rle = |w: u16, codes: &[u8]| {
        let mut b = header(&format!("-Y 1 +X {w}"));
        b.extend_from_slice(&[2, 2, (w >> 8) as u8, w as u8]);
        b.extend_from_slice(codes);
        b
    };
    assert!(matches!(
        err(&rle(8, &[128 + 9, 1])),
        ImageError::Scanline { row: 0, .. }
    ));
    assert!(matches!(
        err(&rle(8, &[0])),
        ImageError::Scanline { row: 0, .. }
    ));
    assert!(matches!(
        err(&rle(8, &[9, 1, 2, 3, 4, 5, 6, 7, 8, 9])),
        ImageError::Scanline { .. }
    ));
    assert!(matches!(
        err(&rle(8, &[128 + 8, 1, 128 + 8])),
        ImageError::Truncated { row: 0, .. }
    ));
    let mut b = header("-Y 1 +X 9");
    b.extend_from_slice(&[2, 2, 0, 8, 0, 0, 0, 0]);
    assert!(matches!(err(&b), ImageError::Scanline { .. }));
    // Flat data cut short: the scanline is named.
    let mut b = header("-Y 3 +X 2");
    b.extend_from_slice(&[3u8; 4 * 5]);
    b[header("-Y 3 +X 2").len()] = 9;
    match err(&b) {
        ImageError::Truncated { row, .. } => assert_eq!(row, 2),
        other => panic!("{other:?}"),
    }
}

#[test]
fn hdr_trailing_bytes_are_a_warning() {
    let mut b = write_hdr_flat(&exact_image(3, 2));
    b.extend_from_slice(b"junk");
    let img = read_hdr(&b).unwrap();
    assert_eq!(img.warnings().len(), 1);
}

#[test]
fn pfm_round_trips_both_byte_orders_and_channel_counts() {
    let mut img = exact_image(5, 3);
    img.set_pixel(1, 2, [-0.25, 1e-20, 7.5]);
    for big in [false, true] {
        let back = read_pfm(&write_pfm(&img, false, big)).unwrap();
        assert_eq!(back, img);
        let grey = read_pfm(&write_pfm(&img, true, big)).unwrap();
        for y in 0..3 {
            for x in 0..5 {
                let v = img.pixel(x, y)[0];
                assert_eq!(grey.pixel(x, y), [v, v, v]);
            }
        }
    }
    // Rows are stored bottom to top: the first value of the data is the bottom-left pixel.
    let bytes = write_pfm(&img, true, false);
    let data_start = bytes.len() - 5 * 3 * 4;
    let first = f32::from_le_bytes(bytes[data_start..data_start + 4].try_into().unwrap());
    assert_eq!(first, img.pixel(0, 2)[0]);
}

#[test]
fn pfm_scale_header_variants_and_errors() {
    let data = |n: usize| -> Vec<u8> { (0..n).flat_map(|k| (k as f32).to_le_bytes()).collect() };
    // Header on one line, scale magnitude 2 multiplies.
    let mut b = b"Pf 2 1 -2.0\n".to_vec();
    b.extend(data(2));
    let img = read_pfm(&b).unwrap();
    assert_eq!(img.pixel(1, 0), [2.0, 2.0, 2.0]);
    let err = |b: &[u8]| read_pfm(b).unwrap_err();
    assert!(matches!(
        err(b"P6\n1 1\n"),
        ImageError::Header { line: 1, .. }
    ));
    assert!(matches!(err(b"PF\n1\n"), ImageError::Header { .. }));
    assert!(matches!(
        err(b"PF\nx 1\n-1\n"),
        ImageError::Header { line: 2, .. }
    ));
    assert!(matches!(
        err(b"PF\n2 x\n-1\n"),
        ImageError::Header {
            line: 2,
            column: 3,
            ..
        }
    ));
    assert!(matches!(
        err(b"PF\n1 1\n0\n"),
        ImageError::Header { line: 3, .. }
    ));
    assert!(matches!(err(b"PF\n1 1\nnan\n"), ImageError::Header { .. }));
    assert!(matches!(err(b"PF\n0 1\n-1\n"), ImageError::BadSize { .. }));
    assert!(matches!(
        err(b"PF\n99999999 99999999\n-1\n"),
        ImageError::BadSize { .. }
    ));
    match err(b"PF\n4000 4000\n-1\n\0\0\0\0") {
        ImageError::Truncated {
            needed,
            present,
            row: 0,
            ..
        } => {
            assert_eq!(needed, 16 + 4000 * 4000 * 12);
            assert_eq!(present, 20);
        }
        other => panic!("{other:?}"),
    }
    let mut b = b"Pf\n1 2\n-1\n".to_vec();
    b.extend(1f32.to_le_bytes());
    b.extend(f32::NAN.to_le_bytes());
    // The second value of the file is the top row (rows go bottom to top).
    assert!(matches!(err(&b), ImageError::NonFinite { x: 0, y: 0, .. }));
    let mut b = b"Pf\n1 1\n-1\n".to_vec();
    b.extend(1f32.to_le_bytes());
    b.extend(b"xx");
    assert_eq!(read_pfm(&b).unwrap().warnings().len(), 1);
}

fn exr_bytes(image: impl FnOnce(&mut std::io::Cursor<Vec<u8>>)) -> Vec<u8> {
    let mut c = std::io::Cursor::new(Vec::new());
    image(&mut c);
    c.into_inner()
}

#[test]
fn exr_rgb_rgba_y_half_float_scanline_tiled() {
    use exr::prelude::*;
    let (w, h) = (13usize, 7usize);
    let val = |x: usize, y: usize, c: usize| ((x * 3 + y * 5 + c) % 17) as f32 * 0.25;
    // RGB f32, scanlines (the crate's default encoding for small images).
    let rgb = exr_bytes(|c| {
        exr::image::Image::from_channels(
            (w, h),
            SpecificChannels::rgb(|p: Vec2<usize>| {
                (val(p.0, p.1, 0), val(p.0, p.1, 1), val(p.0, p.1, 2))
            }),
        )
        .write()
        .to_buffered(c)
        .unwrap()
    });
    // RGBA f16, tiled.
    let rgba = exr_bytes(|c| {
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("main"),
            Encoding {
                blocks: Blocks::Tiles(Vec2(4, 4)),
                ..Encoding::FAST_LOSSLESS
            },
            SpecificChannels::rgba(|p: Vec2<usize>| {
                (
                    f16::from_f32(val(p.0, p.1, 0)),
                    f16::from_f32(val(p.0, p.1, 1)),
                    f16::from_f32(val(p.0, p.1, 2)),
                    f16::from_f32(1.0),
                )
            }),
        );
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(c)
            .unwrap()
    });
    // Y only, f32.
    let y = exr_bytes(|c| {
        let samples: Vec<f32> = (0..w * h).map(|k| val(k % w, k / w, 0)).collect();
        let chans = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            "Y",
            FlatSamples::F32(samples),
        )]));
        exr::image::Image::from_channels((w, h), chans)
            .write()
            .to_buffered(c)
            .unwrap()
    });
    for (name, bytes, grey) in [
        ("rgb", &rgb, false),
        ("rgba", &rgba, false),
        ("y", &y, true),
    ] {
        let img = super::Image::from_bytes(bytes, None).unwrap();
        assert_eq!((img.width(), img.height()), (w, h), "{name}");
        for yy in 0..h {
            for x in 0..w {
                let want = if grey {
                    [val(x, yy, 0); 3]
                } else {
                    [val(x, yy, 0), val(x, yy, 1), val(x, yy, 2)]
                };
                assert_eq!(img.pixel(x, yy), want, "{name} at ({x}, {yy})");
            }
        }
        assert_eq!(img.warnings().len(), usize::from(name == "rgba"), "{name}");
    }
    // Cut files and garbage are errors, not panics.
    for cut in [8, 40, rgb.len() / 2, rgb.len() - 1] {
        assert!(read_exr(&rgb[..cut]).is_err(), "cut at {cut}");
    }
    assert!(read_exr(&[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 0xff]).is_err());
}

#[test]
fn format_detection() {
    assert_eq!(ImageFormat::sniff(b"#?RADIANCE"), Some(ImageFormat::Hdr));
    assert_eq!(ImageFormat::sniff(b"Pf\n"), Some(ImageFormat::Pfm));
    assert_eq!(
        ImageFormat::from_path(Path::new("a/b.EXR")),
        Some(ImageFormat::Exr)
    );
    assert!(matches!(
        Image::from_bytes(b"GIF89a", None),
        Err(ImageError::UnknownFormat { .. })
    ));
    assert!(matches!(
        Image::read(Path::new("/nonexistent/x.hdr")),
        Err(ImageError::File(
            crate::input::file::ReadFileError::NotFound { .. }
        ))
    ));
    // Not a regular file: refused by the one file reader, never read.
    assert!(matches!(
        Image::read(Path::new("/dev/zero")),
        Err(ImageError::File(
            crate::input::file::ReadFileError::NotRegular { .. }
        ))
    ));
}

/// A small tiled file whose header declares `n` float channels on a 8192 × 4096 data window with
/// one tile of that size (the data windows and the tile size patched into a 16 × 16 file the
/// `exr` crate wrote): a few kilobytes that would decode to n × 128 MiB.
fn exr_many_channels(n: usize) -> Vec<u8> {
    use exr::prelude::*;
    let mut list = vec![AnyChannel::new("Y", FlatSamples::F32(vec![1.0; 256]))];
    for k in 0..n - 1 {
        list.push(AnyChannel::new(
            format!("c{k:04}").as_str(),
            FlatSamples::F32(vec![0.5; 256]),
        ));
    }
    let enc = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::Tiles(Vec2(16, 16)),
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (16, 16),
        LayerAttributes::default(),
        enc,
        AnyChannels::sort(SmallVec::from_vec(list)),
    );
    let mut b = exr_bytes(|c| {
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(c)
            .unwrap()
    });
    let find = |b: &[u8], pat: &[u8]| b.windows(pat.len()).position(|w| w == pat).unwrap();
    let (w, h) = (8192i32, 4096i32);
    for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let p = find(&b, name) + name.len() + 4;
        b[p + 8..p + 12].copy_from_slice(&(w - 1).to_le_bytes());
        b[p + 12..p + 16].copy_from_slice(&(h - 1).to_le_bytes());
    }
    let p = find(&b, b"tiles\0tiledesc\0") + 15 + 4;
    b[p..p + 4].copy_from_slice(&(w as u32).to_le_bytes());
    b[p + 4..p + 8].copy_from_slice(&(h as u32).to_le_bytes());
    b
}

#[test]
fn exr_channels_that_would_decode_past_the_limit_are_refused_before_decoding() {
    // 40 channels × 4 bytes × 2^25 pixels = 5 GiB from a file of a few kilobytes (found by hand
    // after the `exr` fuzz target; 200 channels aborted the process in the decoder's inflate).
    let b = exr_many_channels(40);
    assert!(b.len() < 8192, "{}", b.len());
    match read_exr(&b) {
        Err(ImageError::BadSize {
            width: 8192,
            height: 4096,
            message,
            ..
        }) => assert!(message.contains("40 channels"), "{message}"),
        other => panic!("expected BadSize, got {other:?}"),
    }
    // Two channels, 256 MiB: under the limit, so the header passes and the decoder runs (and
    // then finds the tile's data short, or decodes it).
    assert!(!matches!(
        read_exr(&exr_many_channels(2)),
        Err(ImageError::BadSize { .. })
    ));
}

#[test]
fn exr_b44_block_that_overflows_the_decoder_is_no_panic() {
    // The `exr` fuzz target's crash (minimised): a 4 × 4 Y half B44 file whose packed block makes
    // the crate's `unpack14` subtract with overflow: a panic with overflow checks (test builds),
    // a wrapped value without (release, as OpenEXR's own code does, which decodes to NaN and is
    // refused as a non-finite pixel). Either way no panic escapes `read_exr`: an error, or an
    // image of finite values.
    let hex = "762f3101020000006368756e6b436f756e7400696e740004000000010000006368616e6e656c730063686c697374001300000059000100000000000000010000000100000000636f6d7072657373696f6e00636f6d7072657373696f6e0001000000066c696e654f72646572006c696e654f72646572000100000000646973706c617957696e646f7700626f783269001000000000000000000000000300000003000000706978656c417370656374526174696f00666c6f617400040000000000803f73637265656e57696e646f7743656e746572007632660008000000000000000000000073637265656e57696e646f77576964746800666c6f617400040000000000803f6461746157696e646f7700626f7832690010000000000000000000000003000000030000007479706500737472696e67000d0000007363616e6c696e65696d616765005101000000000000000000000e0000000000040000000000000000000000";
    let b: Vec<u8> = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect();
    match read_exr(&b) {
        Ok(img) => assert!(img.rgb().iter().all(|v| v.is_finite())),
        Err(ImageError::Exr { .. } | ImageError::NonFinite { .. }) => {}
        Err(e) => panic!("unexpected error {e:?}"),
    }
}

#[test]
fn exr_channels_come_from_one_layer() {
    use super::openexr::pick_channels as pick;
    use exr::prelude::*;
    let n = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    // Unprefixed RGB wins over layers; a layer missing G is skipped, not mixed with another.
    assert_eq!(pick(&n(&["A.R", "B", "G", "R", "Z"])), Some(vec![3, 2, 1]));
    assert_eq!(
        pick(&n(&[
            "AO.R",
            "Combined.B",
            "Combined.G",
            "Combined.R",
            "Depth.Z"
        ])),
        Some(vec![3, 2, 1])
    );
    assert_eq!(pick(&n(&["a.R", "a.B", "b.G", "Y"])), Some(vec![3, 3, 3]));
    assert_eq!(pick(&n(&["a.R", "b.G", "c.B"])), None);
    // A file: the R of a first layer without G must not be read with another layer's G and B.
    let (w, h) = (4, 2);
    let ch = |name: &str, v: f32| AnyChannel::new(name, FlatSamples::F32(vec![v; w * h]));
    let list = vec![
        ch("AO.R", 9.0),
        ch("View.B", 3.0),
        ch("View.G", 2.0),
        ch("View.R", 1.0),
    ];
    let b = exr_bytes(|c| {
        exr::image::Image::from_channels((w, h), AnyChannels::sort(SmallVec::from_vec(list)))
            .write()
            .to_buffered(c)
            .unwrap()
    });
    let img = read_exr(&b).unwrap();
    assert_eq!(img.pixel(0, 0), [1.0, 2.0, 3.0]);
    assert!(img.warnings()[0].contains("AO.R"), "{:?}", img.warnings());
}

/// Issue 40: `PF\n2 2\n-1.0\r\n` then twelve floats 0.7 was read one byte off (every pixel 4.17e-8)
/// with only a trailing-byte warning. The `\r\n` is now taken as the separator when the length says
/// so, and refused with its byte offset when it is ambiguous.
#[test]
fn pfm_crlf_after_the_scale_is_never_read_one_byte_off() {
    let mut b = b"PF\n2 2\n-1.0\r\n".to_vec();
    for _ in 0..12 {
        b.extend(0.7f32.to_le_bytes());
    }
    let img = read_pfm(&b).unwrap();
    for y in 0..2 {
        for x in 0..2 {
            assert_eq!(img.pixel(x, y), [0.7, 0.7, 0.7]);
        }
    }
    assert_eq!(img.warnings().len(), 1, "{:?}", img.warnings());
    assert!(img.warnings()[0].contains("\\r\\n"), "{:?}", img.warnings());
    // One more byte: the "\n" could be data or separator: refused, located at the "\r".
    let mut c = b.clone();
    c.push(0);
    match read_pfm(&c).unwrap_err() {
        ImageError::Header {
            line,
            offset,
            message,
            ..
        } => {
            assert_eq!((line, offset), (3, 11), "{message}");
            assert!(message.contains("\\r\\n"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // Exactly the data after "\r": the "\n" is the first data byte, as the format says.
    let mut d = b"Pf\n1 1\n-1\r".to_vec();
    d.extend([b'\n', 0, 0, 0]);
    let img = read_pfm(&d).unwrap();
    assert_eq!(img.pixel(0, 0)[0], f32::from_le_bytes([b'\n', 0, 0, 0]));
    assert!(img.warnings().is_empty());
}

/// Issue 40: a 786 KB `.hdr` (`-Y 65536 +X 512`, each scanline one pixel then old-style repeats of
/// 255 and 256) declared 33.5 million pixels and cost 2.4 GB. Refused before allocating; the same
/// scanlines for an image of 2²⁰ pixels are read.
#[test]
fn hdr_declared_size_must_be_plausible_for_the_bytes_present() {
    let file = |height: usize| {
        let mut b =
            format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X 512\n").into_bytes();
        for _ in 0..height {
            b.extend([128, 64, 32, 129, 1, 1, 1, 0xFF, 1, 1, 1, 1]);
        }
        b
    };
    let big = file(65536);
    assert!(big.len() < 800_000);
    match read_hdr(&big).unwrap_err() {
        ImageError::Header { line, message, .. } => {
            assert_eq!(line, 4, "{message}");
            assert!(message.contains("implausible"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let ok = read_hdr(&file(2048)).unwrap();
    assert_eq!((ok.width(), ok.height()), (512, 2048));
    assert_eq!(ok.pixel(511, 2047), ok.pixel(0, 0));
}

/// Issue 40: an uncompressed 4 × 3 RGB EXR whose chunks all say y = 0 was read with rows 1–2
/// black and no warning; refused now, naming the chunk. A chunk missing (truncated file) too.
#[test]
fn exr_chunks_must_cover_every_row_exactly_once() {
    use exr::prelude::*;
    let good = exr_bytes(|c| {
        let layer = Layer::new(
            (4, 3),
            LayerAttributes::named("main"),
            Encoding::UNCOMPRESSED,
            SpecificChannels::rgb(|p: Vec2<usize>| (p.0 as f32 + 1.0, p.1 as f32 + 1.0, 0.5f32)),
        );
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(c)
            .unwrap()
    });
    let img = read_exr(&good).unwrap();
    assert_eq!(img.pixel(3, 2), [4.0, 3.0, 0.5]);
    // The offset table: three u64 offsets, the first pointing just after the table.
    let u64_at = |b: &[u8], p: usize| u64::from_le_bytes(b[p..p + 8].try_into().unwrap()) as usize;
    let table = (0..good.len() - 24)
        .find(|&p| {
            let (a, b, c) = (
                u64_at(&good, p),
                u64_at(&good, p + 8),
                u64_at(&good, p + 16),
            );
            a == p + 24 && a < b && b < c && c < good.len()
        })
        .expect("offset table");
    let mut bad = good.clone();
    for k in 1..3 {
        let chunk = u64_at(&good, table + 8 * k);
        assert_eq!(
            i32::from_le_bytes(good[chunk..chunk + 4].try_into().unwrap()),
            k as i32
        );
        bad[chunk..chunk + 4].copy_from_slice(&0i32.to_le_bytes());
    }
    let e = read_exr(&bad).unwrap_err().to_string();
    assert!(e.contains("chunk 1") && e.contains("second time"), "{e}");
    // A y outside the data window.
    let mut out = good.clone();
    let chunk = u64_at(&good, table + 16);
    out[chunk..chunk + 4].copy_from_slice(&7i32.to_le_bytes());
    let e = read_exr(&out).unwrap_err().to_string();
    assert!(e.contains("chunk 2") && e.contains("y = 7"), "{e}");
}

/// Issue 40: the pixel limit is raised to 16384 × 8192 and settable. (The limit set here stays
/// far above every other test's images, which may be read concurrently.)
#[test]
fn the_pixel_limit_admits_16k_skies_and_is_settable() {
    assert_eq!(super::MAX_PIXELS, 16384 * 8192);
    let mut b = b"#?RADIANCE\n\n-Y 8192 +X 16384\n".to_vec();
    b.extend(std::iter::repeat_n([1u8, 2, 3, 128], 8192).flatten());
    // Within the default limit: refused by the plausibility check, not by the size.
    assert!(matches!(read_hdr(&b), Err(ImageError::Header { .. })));
    let before = super::set_max_pixels(1 << 26);
    let e = read_hdr(&b).unwrap_err();
    super::set_max_pixels(before);
    match e {
        ImageError::BadSize { message, .. } => assert!(message.contains("67108864"), "{message}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(super::max_pixels(), before);
    assert!(super::max_exr_decoded_bytes() >= 16 * 16384 * 8192);
}
