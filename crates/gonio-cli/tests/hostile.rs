//! Hostile paths, devices and sizes (issue 15): the CLI reads only regular files, bounded in size,
//! and never replaces a device, a FIFO, a link or an input file. One test per row of the issue's
//! table; devices and FIFOs are made in a temporary folder (`mknod`, `mkfifo`) where the system
//! allows it, else the real `/dev/null` and `/dev/full` are used (this code never replaces them).
#![cfg(unix)]

use std::fs;
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

mod common;
use common::*;

/// A small valid IES file (type C, 3 × 2 nodes) with the given TILT line value.
fn ies_text(tilt: &str) -> String {
    format!(
        "IESNA:LM-63-2002\n[TEST] hostile\nTILT={tilt}\n1 1000 1 3 2 1 2 0.5 0.5 0.1\n1 1 100\n\
         0 45 90\n0 90\n100 80 10\n100 70 20\n"
    )
}

fn write_ies(dir: &Path, name: &str, tilt: &str) -> PathBuf {
    let p = dir.join(name);
    fs::write(&p, ies_text(tilt)).unwrap();
    p
}

/// Temporary files `gonio` left in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".gonio-tmp-"))
        .collect()
}

fn mkfifo(p: &Path) {
    let c = std::ffi::CString::new(s(p)).unwrap();
    // SAFETY: a valid NUL-terminated path.
    let r = unsafe { libc::mkfifo(c.as_ptr(), 0o644) };
    assert_eq!(r, 0, "mkfifo {}", p.display());
}

/// A character device node `major:minor` at `p` if the system lets us make one (root, a
/// filesystem without `nodev`) and it works; else `None`.
fn mknod_char(p: &Path, major: u32, minor: u32) -> Option<PathBuf> {
    let c = std::ffi::CString::new(s(p)).unwrap();
    // SAFETY: a valid NUL-terminated path.
    let r = unsafe {
        libc::mknod(
            c.as_ptr(),
            libc::S_IFCHR | 0o666,
            libc::makedev(major, minor),
        )
    };
    if r != 0 {
        return None;
    }
    // A `nodev` mount lets us make the node but not open it.
    match fs::OpenOptions::new().write(true).open(p) {
        Ok(_) => Some(p.to_path_buf()),
        Err(_) => {
            let _ = fs::remove_file(p);
            None
        }
    }
}

/// A device to test with: one made in `dir`, else the system's (`/dev/null`, …), which this
/// code only ever opens and writes directly.
fn device(dir: &Path, name: &str, major: u32, minor: u32, system: &str) -> PathBuf {
    match mknod_char(&dir.join(name), major, minor) {
        Some(p) => p,
        None => {
            eprintln!(
                "note: cannot make a device node in {} (not root or a nodev mount); using {system}",
                dir.display()
            );
            PathBuf::from(system)
        }
    }
}

fn is_char_device(p: &Path, major_minor: (u32, u32)) -> bool {
    let m = fs::symlink_metadata(p).unwrap();
    let rdev = m.rdev();
    m.file_type().is_char_device() && (libc::major(rdev), libc::minor(rdev)) == major_minor
}

// ---------------------------------------------------------------------------------------------
// Reading

/// Row 1: `TILT=link`, a symbolic link next to the IES file pointing outside its folder, is
/// refused without reading (or echoing) the target; a link inside the folder is followed.
#[test]
fn tilt_symlink_leaving_the_folder_is_refused_and_nothing_is_echoed() {
    let secret_dir = temp_dir("secret");
    let secret = secret_dir.join("passwd");
    fs::write(&secret, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let dir = temp_dir("tilt-link");
    std::os::unix::fs::symlink(&secret, dir.join("link_passwd")).unwrap();
    let ies = write_ies(&dir, "lamp.ies", "link_passwd");
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(err.contains("outside the IES file's folder"), "{err}");
    assert!(
        !err.contains("root:x"),
        "the target's content is echoed: {err}"
    );
    // The same through `..` in the link target, relative.
    std::os::unix::fs::symlink(
        Path::new("..")
            .join(secret_dir.file_name().unwrap())
            .join("passwd"),
        dir.join("rel_link"),
    )
    .unwrap();
    let ies = write_ies(&dir, "lamp2.ies", "rel_link");
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(err.contains("outside the IES file's folder"), "{err}");
    // A link to a TILT file inside the folder is fine.
    fs::write(dir.join("real.tlt"), "1\n2\n0 90\n1 0.5\n").unwrap();
    std::os::unix::fs::symlink("real.tlt", dir.join("inside_link")).unwrap();
    let ies = write_ies(&dir, "lamp3.ies", "inside_link");
    let out = ok(&["info", s(&ies)]);
    assert!(out.contains("inside_link"), "{out}");
    // A TILT file inside the folder with junk: the message quotes at most a short, escaped
    // excerpt.
    let junk = format!("\x1b[31m{}\n", "A".repeat(5000));
    fs::write(dir.join("junk.tlt"), junk).unwrap();
    let ies = write_ies(&dir, "lamp4.ies", "junk.tlt");
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(
        !err.contains('\x1b'),
        "an escape character is echoed: {err:?}"
    );
    assert!(
        !err.contains(&"A".repeat(100)),
        "a long excerpt is echoed: {err}"
    );
    assert!(err.len() < 600, "message of {} bytes", err.len());
}

/// Row 2: a FIFO as the TILT file or as the input is refused at once (nothing blocks).
#[test]
fn fifos_are_refused_without_blocking() {
    let dir = temp_dir("fifo");
    mkfifo(&dir.join("fifo"));
    let ies = write_ies(&dir, "lamp.ies", "fifo");
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(err.contains("not a regular file"), "{err}");
    mkfifo(&dir.join("fifo.ies"));
    let err = fails_with(1, &["info", s(&dir.join("fifo.ies"))]);
    assert!(
        err.contains("FIFO") && err.contains("only regular files"),
        "{err}"
    );
    mkfifo(&dir.join("fifo.json"));
    let err = fails_with(1, &["sample", s(&dir.join("fifo.json")), "-n", "1"]);
    assert!(err.contains("FIFO"), "{err}");
    // A FIFO as the CSV of points or directions.
    mkfifo(&dir.join("points.csv"));
    let err = fails_with(
        1,
        &["sample", "example", "--points", s(&dir.join("points.csv"))],
    );
    assert!(err.contains("FIFO"), "{err}");
}

/// Row 3: an input or TILT file that is (a link to) a device such as `/dev/zero` is refused
/// before anything is read.
#[test]
fn devices_as_inputs_are_refused() {
    let dir = temp_dir("zero");
    let zero = device(&dir, "zero", 1, 5, "/dev/zero");
    std::os::unix::fs::symlink(&zero, dir.join("zero.ies")).unwrap();
    let err = fails_with(1, &["info", s(&dir.join("zero.ies"))]);
    assert!(err.contains("character device"), "{err}");
    std::os::unix::fs::symlink(&zero, dir.join("zero.json")).unwrap();
    let err = fails_with(1, &["info", s(&dir.join("zero.json"))]);
    assert!(err.contains("character device"), "{err}");
    // A device node named as the TILT file, inside the folder.
    if zero.starts_with(&dir) {
        let ies = write_ies(&dir, "lamp.ies", "zero");
        let err = fails_with(1, &["info", s(&ies)]);
        assert!(err.contains("not a regular file"), "{err}");
    }
    // A link to the system's /dev/zero next to the IES file leaves the folder.
    std::os::unix::fs::symlink("/dev/zero", dir.join("devzero")).unwrap();
    let ies = write_ies(&dir, "lamp2.ies", "devzero");
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(err.contains("outside the IES file's folder"), "{err}");
    // A directory is not a file either.
    fs::create_dir(dir.join("d.ies")).unwrap();
    let err = fails_with(1, &["info", s(&dir.join("d.ies"))]);
    assert!(err.contains("directory"), "{err}");
}

/// Row 4: a file over the documented limit (64 MiB) is refused before it is read (the test file
/// is sparse: it takes no disk space); trailing data within the limit is read and warned about.
#[test]
fn oversized_inputs_are_refused_before_reading() {
    let dir = temp_dir("big");
    let ies = dir.join("big.ies");
    fs::write(&ies, ies_text("NONE")).unwrap();
    let f = fs::OpenOptions::new().write(true).open(&ies).unwrap();
    f.set_len((64 << 20) + 1).unwrap();
    drop(f);
    let start = Instant::now();
    let err = fails_with(1, &["info", s(&ies)]);
    assert!(
        err.contains("more than the limit of 67108864 bytes"),
        "{err}"
    );
    println!("refused in {:?}", start.elapsed());
    // Exactly at the limit is read: the NUL bytes after the table are one trailing token.
    let f = fs::OpenOptions::new().write(true).open(&ies).unwrap();
    f.set_len(64 << 20).unwrap();
    drop(f);
    let out = ok(&["info", s(&ies)]);
    assert!(out.contains("1 trailing tokens"), "{out}");
    // Row 5: a JSON file over the node cap is over the size limit: refused before parsing.
    let json = dir.join("huge.json");
    let f = fs::File::create(&json).unwrap();
    f.set_len(134_217_728 + 2).unwrap();
    drop(f);
    let err = fails_with(1, &["info", s(&json)]);
    assert!(err.contains("more than the limit"), "{err}");
    // A header of more than 10000 lines before `TILT=` is refused at the line where the limit is
    // passed (a hostile header used to cost a warning and a string per line: 3.7 GB for 60 MB).
    let p = dir.join("header.ies");
    fs::write(
        &p,
        format!(
            "IESNA:LM-63-2002\n{}{}",
            "a\n".repeat(20_000),
            ies_text("NONE")
        ),
    )
    .unwrap();
    let err = fails_with(1, &["info", s(&p)]);
    assert!(
        err.contains(":10002:1: no `TILT=` line within the first 10000 header lines"),
        "{err}"
    );
    // Trailing data after the table: a warning that says where it starts.
    let mut text = ies_text("NONE");
    text.push_str(&"0\n".repeat(1000));
    let p = dir.join("trailing.ies");
    fs::write(&p, text).unwrap();
    let out = ok(&["info", s(&p)]);
    assert!(out.contains("1000 trailing tokens"), "{out}");
}

// ---------------------------------------------------------------------------------------------
// Writing

/// Row 6: `-o` onto a character device writes to it directly (never replaced, no temporary file);
/// `/dev/full` gives a clear error and stays a device.
#[test]
fn devices_as_outputs_are_written_directly() {
    let dir = temp_dir("dev-out");
    let null = device(&dir, "null", 1, 3, "/dev/null");
    let out = ok(&["sample", "example", "-n", "1000", "-o", s(&null)]);
    assert!(out.is_empty());
    assert!(
        is_char_device(&null, (1, 3)),
        "{} was replaced",
        null.display()
    );
    assert!(leftovers(null.parent().unwrap()).is_empty());
    let full = device(&dir, "full", 1, 7, "/dev/full");
    let err = fails_with(1, &["sample", "example", "-n", "1000", "-o", s(&full)]);
    assert!(err.contains("No space left on device"), "{err}");
    assert!(
        err.contains(s(&full)),
        "the message names the output: {err}"
    );
    assert!(
        is_char_device(&full, (1, 7)),
        "{} was replaced",
        full.display()
    );
    assert!(leftovers(full.parent().unwrap()).is_empty());
    // convert, through a symbolic link named with the format's extension: the link is followed
    // to the device, which is written directly.
    std::os::unix::fs::symlink(&null, dir.join("out.ies")).unwrap();
    ok(&["convert", "example", s(&dir.join("out.ies"))]);
    assert!(is_char_device(&null, (1, 3)));
    assert!(fs::symlink_metadata(dir.join("out.ies"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(leftovers(&dir).is_empty());
}

/// Row 6: `-o` onto a FIFO writes into the FIFO (a reader gets the rows), never replaces it.
#[test]
fn fifo_as_output_is_written_directly() {
    let dir = temp_dir("fifo-out");
    let fifo = dir.join("out.csv");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || fs::read_to_string(fifo).unwrap())
    };
    ok(&["sample", "example", "-n", "5", "-o", s(&fifo)]);
    let text = reader.join().unwrap();
    assert_eq!(text.lines().count(), 6, "{text}");
    assert!(text.starts_with("u,v,x,y,z,pdf\n"));
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(leftovers(&dir).is_empty());
}

/// Row 6: `-o` onto a symbolic link writes through to its target (the link stays); a link to a
/// missing file is refused; the mode of an existing file is kept; hard links stay linked.
#[test]
fn links_and_modes_survive_a_write() {
    let dir = temp_dir("links");
    let target = dir.join("target.csv");
    fs::write(&target, "old\n").unwrap();
    fs::set_permissions(&target, fs::Permissions::from_mode(0o600)).unwrap();
    std::os::unix::fs::symlink("target.csv", dir.join("link.csv")).unwrap();
    ok(&[
        "sample",
        "example",
        "-n",
        "3",
        "-o",
        s(&dir.join("link.csv")),
    ]);
    assert!(fs::symlink_metadata(dir.join("link.csv"))
        .unwrap()
        .file_type()
        .is_symlink());
    let text = fs::read_to_string(&target).unwrap();
    assert_eq!(text.lines().count(), 4, "{text}");
    assert_eq!(
        fs::metadata(&target).unwrap().permissions().mode() & 0o7777,
        0o600
    );
    // A dangling link is refused and not replaced.
    std::os::unix::fs::symlink("missing.csv", dir.join("dangling.csv")).unwrap();
    let err = fails_with(
        1,
        &[
            "sample",
            "example",
            "-n",
            "3",
            "-o",
            s(&dir.join("dangling.csv")),
        ],
    );
    assert!(err.contains("symbolic link to a missing file"), "{err}");
    assert!(fs::symlink_metadata(dir.join("dangling.csv"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(!dir.join("missing.csv").exists());
    // Hard links: both names see the new content.
    let a = dir.join("a.csv");
    fs::write(&a, "old\n").unwrap();
    fs::set_permissions(&a, fs::Permissions::from_mode(0o640)).unwrap();
    fs::hard_link(&a, dir.join("b.csv")).unwrap();
    ok(&["sample", "example", "-n", "2", "-o", s(&a)]);
    let b = fs::read_to_string(dir.join("b.csv")).unwrap();
    assert_eq!(b.lines().count(), 3, "{b}");
    assert_eq!(fs::metadata(&a).unwrap().nlink(), 2);
    assert_eq!(
        fs::metadata(&a).unwrap().permissions().mode() & 0o7777,
        0o640
    );
    // A new file gets the usual mode (0666 less the umask), not 0600.
    let new = dir.join("new.csv");
    ok(&["sample", "example", "-n", "2", "-o", s(&new)]);
    // SAFETY: reading and restoring the process umask.
    let umask = unsafe {
        let m = libc::umask(0o022);
        libc::umask(m);
        m
    } as u32;
    assert_eq!(
        fs::metadata(&new).unwrap().permissions().mode() & 0o777,
        0o666 & !umask
    );
    assert!(leftovers(&dir).is_empty());
}

/// Row 7: `-o /dev/null` (the real one) is written directly: no temporary file appears next to
/// it, and it stays the null device.
#[test]
fn dev_null_is_never_replaced() {
    let before: Vec<String> = leftovers(Path::new("/dev"));
    ok(&["sample", "example", "-n", "20000", "-o", "/dev/null"]);
    assert!(is_char_device(Path::new("/dev/null"), (1, 3)));
    assert_eq!(leftovers(Path::new("/dev")), before);
    // `/dev/stdout` is a link to the pipe the test reads: written directly.
    if Path::new("/dev/stdout").exists() {
        let out = ok(&["sample", "example", "-n", "3", "-o", "/dev/stdout"]);
        assert_eq!(out.lines().count(), 4, "{out}");
    }
}

/// Row 8: an output that is the same file as an input (same device and inode: the same name, a
/// hard link, a symbolic link) is refused before anything is written.
#[test]
fn an_input_is_never_overwritten() {
    let dir = temp_dir("same");
    let ies = write_ies(&dir, "in.ies", "NONE");
    let original = fs::read(&ies).unwrap();
    let err = fails_with(1, &["sample", s(&ies), "-n", "5", "-o", s(&ies)]);
    assert!(err.contains("same file as the input"), "{err}");
    let err = fails_with(1, &["convert", s(&ies), s(&ies)]);
    assert!(err.contains("same file as the input"), "{err}");
    fs::hard_link(&ies, dir.join("hard.ies")).unwrap();
    let err = fails_with(1, &["convert", s(&ies), s(&dir.join("hard.ies"))]);
    assert!(err.contains("same file as the input"), "{err}");
    std::os::unix::fs::symlink("in.ies", dir.join("soft.ies")).unwrap();
    let err = fails_with(1, &["convert", s(&dir.join("soft.ies")), s(&ies)]);
    assert!(err.contains("same file as the input"), "{err}");
    // The CSV of points, and a TILT file, are inputs too.
    let pts = dir.join("points.csv");
    fs::write(&pts, "u,v\n0.5,0.5\n").unwrap();
    let err = fails_with(
        1,
        &["sample", "example", "--points", s(&pts), "-o", s(&pts)],
    );
    assert!(err.contains("same file as the input"), "{err}");
    fs::write(dir.join("t.tlt"), "1\n2\n0 90\n1 0.5\n").unwrap();
    let tilted = write_ies(&dir, "tilted.ies", "t.tlt");
    let err = fails_with(
        1,
        &["sample", s(&tilted), "-n", "2", "-o", s(&dir.join("t.tlt"))],
    );
    assert!(err.contains("same file as the input"), "{err}");
    assert_eq!(fs::read(&ies).unwrap(), original);
    assert_eq!(fs::read(&pts).unwrap(), b"u,v\n0.5,0.5\n");
    assert!(leftovers(&dir).is_empty());
}

/// Row 9: SIGINT or SIGTERM during a long `sample -o` leaves no temporary file (and no output).
#[test]
fn interrupted_runs_leave_no_temporary_file() {
    for sig in [libc::SIGINT, libc::SIGTERM] {
        let dir = temp_dir("signal");
        let out = dir.join("big.csv");
        let mut child = spawn(&["sample", "example", "-n", "2000000000", "-o", s(&out)]);
        let start = Instant::now();
        // Wait until the temporary file exists and has data.
        loop {
            let started = fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).any(|e| {
                e.file_name().to_string_lossy().contains(".gonio-tmp-")
                    && e.metadata().map(|m| m.len() > 0).unwrap_or(false)
            });
            if started {
                break;
            }
            assert!(start.elapsed() < HANG, "no temporary file appeared");
            assert!(child.try_wait().unwrap().is_none(), "gonio ended early");
            std::thread::sleep(Duration::from_millis(20));
        }
        // SAFETY: signalling our own child.
        assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, sig) }, 0);
        let status = child.wait().unwrap();
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(sig), "{status:?}");
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
        assert!(!out.exists());
    }
}

/// A PFM sky of `w` × `h` pixels (little-endian, bottom row first), a smooth gradient.
fn write_pfm(path: &Path, w: usize, h: usize) {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(fs::File::create(path).unwrap());
    write!(f, "PF\n{w} {h}\n-1.0\n").unwrap();
    let mut row = Vec::with_capacity(w * 12);
    for r in 0..h {
        row.clear();
        for c in 0..w {
            let v = 0.1 + (r * 7 + c * 3) as f32 / (w + h) as f32;
            for ch in [v, 0.5 * v, 0.25 * v] {
                row.extend_from_slice(&ch.to_le_bytes());
            }
        }
        f.write_all(&row).unwrap();
    }
    f.flush().unwrap();
}

/// Issue 36, item 5: one file reader with one size limit per kind, large enough for real data:
/// a 200 MB sky (4096 × 4096 float RGB PFM) opens, and a file over the image limit (a sparse
/// 4 GiB + 1 file) is refused before it is read with the library's message, the same text the C
/// ABI and Python give (their tests assert the same string).
#[test]
fn a_200_mb_sky_opens_and_the_image_limit_is_the_library_s() {
    let dir = temp_dir("huge-sky");
    let sky = dir.join("sky.pfm");
    write_pfm(&sky, 4096, 4096);
    assert!(fs::metadata(&sky).unwrap().len() > 200_000_000);
    let out = ok(&["info", s(&sky)]);
    assert!(out.contains("4096"), "{out}");
    let big = dir.join("big.pfm");
    fs::File::create(&big)
        .unwrap()
        .set_len((4u64 << 30) + 1)
        .unwrap();
    let err = fails_with(1, &["info", s(&big)]);
    let want = format!(
        "{}: the file has 4294967297 bytes, more than the limit of 4294967296 bytes for image \
         files (4096 MiB; settable); not read",
        s(&big)
    );
    assert!(err.contains(&want), "{err}");
    let _ = fs::remove_dir_all(&dir);
}
