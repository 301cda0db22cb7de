//! `gonio uv` and `gonio bake` end to end on small generated meshes (720 triangles).

use gonio::mesh::generate::{banana, shape_mesh, Shape};
use gonio::mesh::ply::write_ply_binary;
use gonio::mesh::VertexProperty;
use std::path::PathBuf;

mod common;
use common::*;

fn names(dir: &PathBuf) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn uv_and_bake_write_what_they_say() {
    let dir = temp_dir("ok");
    let mut mesh = shape_mesh(&Shape::Head, 6);
    mesh.vertex_properties.push(VertexProperty {
        name: "detail".into(),
        values: mesh.positions.iter().map(|p| 1.0 + p[0].max(0.0)).collect(),
    });
    let ply = dir.join("head.ply");
    std::fs::write(&ply, write_ply_binary(&mesh)).unwrap();
    let p = ply.to_str().unwrap();
    let out = dir.join("head.obj");
    let o = run(&["uv", p, "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("flipped 0, degenerate 0"), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let back = gonio::mesh::obj::read_obj(text.as_bytes()).unwrap();
    assert!(back.mesh.texcoords.len() >= mesh.positions.len());
    assert!(back.mesh.triangles.len() >= mesh.triangles.len());
    // The property weight and a compared layout.
    for extra in [
        &["--density", "property:detail"][..],
        &["--layout", "cube"][..],
        &["--density", "solid-angle", "--center", "0,0,0"][..],
    ] {
        let mut args = vec!["uv", p, "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(
            o.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    // Bake a checkerboard, and a 8 × 4 equirectangular PNG.
    let tex = dir.join("tex.png");
    let obj = dir.join("textured.obj");
    let pv = dir.join("preview.png");
    let o = run(&[
        "bake",
        p,
        "--texture",
        "checker",
        "--resolution",
        "32",
        "-o",
        tex.to_str().unwrap(),
        "--obj",
        obj.to_str().unwrap(),
        "--preview",
        pv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mtl = std::fs::read_to_string(dir.join("textured.mtl")).unwrap();
    assert!(mtl.contains("map_Kd tex.png"));
    assert!(std::fs::read_to_string(&obj)
        .unwrap()
        .contains("mtllib textured.mtl"));
    let png = std::fs::read(&tex).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let eq = dir.join("equirect.png");
    {
        let f = std::fs::File::create(&eq).unwrap();
        let mut enc = png::Encoder::new(f, 8, 4);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let data: Vec<u8> = (0..32)
            .flat_map(|i| [(i * 8) as u8, 0, 255 - (i * 8) as u8])
            .collect();
        enc.write_header().unwrap().write_image_data(&data).unwrap();
    }
    ok(&[
        "bake",
        p,
        "--texture",
        eq.to_str().unwrap(),
        "--resolution=16",
        "-o",
        tex.to_str().unwrap(),
    ]);
    // A constant high-dynamic-range lat-long image (PFM, linear values) bakes to a constant texture
    // everywhere (0.502, 0.254 and 2.0 clamped: 128, 65, 255 in 8 bits).
    let pfm = dir.join("sky.pfm");
    let sky = gonio::image::Image::constant(8, 4, [0.502, 0.254, 2.0]).unwrap();
    std::fs::write(&pfm, gonio::image::write_pfm(&sky, false, false)).unwrap();
    let hdr_tex = dir.join("sky.png");
    let (texture, out) = (pfm.to_str().unwrap(), hdr_tex.to_str().unwrap());
    ok(&["bake", p, "--texture", texture, "--resolution=8", "-o", out]);
    {
        let dec = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&hdr_tex).unwrap(),
        ));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0u8; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        let px = &buf[..info.buffer_size()];
        assert!(
            px.chunks_exact(3).all(|c| c == [128, 65, 255]),
            "{:?}",
            &px[..12]
        );
    }
    std::fs::remove_file(&pfm).unwrap();
    std::fs::remove_file(&hdr_tex).unwrap();
    // Nothing else was left in the folder (no temporary files).
    assert_eq!(
        names(&dir),
        vec![
            "equirect.png",
            "head.obj",
            "head.ply",
            "preview.png",
            "tex.png",
            "textured.mtl",
            "textured.obj"
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_meshes_and_outputs_are_refused() {
    let dir = temp_dir("bad");
    let b = dir.join("banana.ply");
    std::fs::write(&b, write_ply_binary(&banana(6))).unwrap();
    let out = dir.join("out.obj");
    let o = run(&["uv", b.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not star-shaped"));
    assert!(!out.exists());
    // The output may not replace the input.
    let o = run(&["uv", b.to_str().unwrap(), "-o", b.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    // A syntax error is located.
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let o = run(&["uv", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("line 3") && e.contains("index 9"), "{e}");
    // A directory is not a regular file.
    let o = run(&["uv", dir.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 40: `bake -o t.png --obj t.png` exited 0 with t.png holding the OBJ text, and `--obj`
/// naming the input mesh was refused only after the PNG was written. Every output is checked
/// against the others and the inputs before anything is written.
#[test]
fn bake_checks_every_output_before_writing_any() {
    let dir = temp_dir("bake-outputs");
    let ply = dir.join("m.ply");
    std::fs::write(&ply, write_ply_binary(&shape_mesh(&Shape::Head, 3))).unwrap();
    let p = ply.to_str().unwrap();
    let png = dir.join("t.png");
    let t = png.to_str().unwrap();
    let bake = |extra: &[&str]| {
        let mut args = vec![
            "bake",
            p,
            "--texture",
            "checker",
            "--resolution",
            "16",
            "-o",
            t,
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    let same_dir_other_spelling = dir.join(".").join("t.png");
    for extra in [
        &["--obj", t][..],
        &["--obj", same_dir_other_spelling.to_str().unwrap()][..],
        &["--preview", t][..],
        &[
            "--obj",
            dir.join("t.mtl").to_str().unwrap(),
            "--preview",
            dir.join("x.png").to_str().unwrap(),
        ][..],
    ] {
        let o = bake(extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?}: {err}");
        assert!(
            err.contains("same destination") && err.contains("nothing written"),
            "{extra:?}: {err}"
        );
        assert_eq!(names(&dir), ["m.ply"], "{extra:?}");
    }
    // --obj naming the input mesh: refused, and the PNG not written either.
    let o = bake(&["--obj", p]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("nothing written"), "{err}");
    assert_eq!(names(&dir), ["m.ply"]);
    // Distinct outputs: all written.
    let o = bake(&["--obj", dir.join("t.obj").to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(names(&dir), ["m.ply", "t.mtl", "t.obj", "t.png"]);
}
