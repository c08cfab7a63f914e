//! Where an output goes: a regular file is replaced atomically (a temporary renamed
//! onto it); a device or a FIFO is written in place and stays what it was; a
//! directory, a read-only folder or a missing folder is a clear error.
//!
//! The device is a private node made with `mknod` in a temporary folder — `c 1 7`,
//! the same driver as the machine's full device — never the machine's own `/dev`
//! entries. Where `mknod` is not permitted (not root, a container without the
//! capability) the test says so and returns.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::*;

/// The exit code of an input or output error (`stages::exit_code::IO`).
const IO: i32 = splinecontact::stages::exit_code::IO as i32;

fn box_msh() -> std::path::PathBuf {
    repo().join("tests/data/msh/box2_v41_ascii.msh")
}

fn is_char_device(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_char_device())
}

fn is_fifo(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_fifo())
}

/// A full device of our own: fails every write with ENOSPC. The import reports it,
/// names the path, exits non-zero, and the node is still a character device.
#[test]
fn a_full_device_is_written_in_place_and_its_error_reported() {
    let dir = tempdir();
    let full = dir.path().join("full");
    let made = Command::new("mknod").arg(&full).args(["c", "1", "7"]).output();
    match made {
        Ok(o) if o.status.success() && is_char_device(&full) => {}
        Ok(o) => {
            eprintln!("SKIPPED a_full_device_is_written_in_place_and_its_error_reported: mknod is not permitted here: {}", String::from_utf8_lossy(&o.stderr).trim());
            return;
        }
        Err(e) => {
            eprintln!("SKIPPED a_full_device_is_written_in_place_and_its_error_reported: no mknod: {e}");
            return;
        }
    }
    let input = box_msh();
    let o = run("sc-import", &[input.to_str().unwrap(), "-o", "full"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(IO), "{err}");
    assert!(err.contains("full: cannot write") && err.contains("No space left on device"), "{err}");
    assert!(!err.contains("wrote"), "{err}");
    assert!(is_char_device(&full), "the device node was replaced");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "files left beside the device: {names:?}");
    // another stage, another writer (write_atomic_with)
    let o = run("sc-import", &[input.to_str().unwrap(), "-o", "box.scmesh", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run("sc-export", &["box.scmesh", "-o", "full", "--format", "yaml"], dir.path());
    assert!(!o.status.success() && stderr(&o).contains("No space left on device"), "{}", stderr(&o));
    assert!(is_char_device(&full), "the device node was replaced by sc-export");
}

/// A FIFO is written in place: what comes out of it is the whole `.scmesh`, and the
/// FIFO is still a FIFO afterwards.
#[test]
fn a_fifo_is_written_in_place() {
    let dir = tempdir();
    let fifo = dir.path().join("pipe.scmesh");
    match Command::new("mkfifo").arg(&fifo).status() {
        Ok(s) if s.success() => {}
        other => {
            eprintln!("SKIPPED a_fifo_is_written_in_place: mkfifo failed: {other:?}");
            return;
        }
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_sc-import"))
        .args([box_msh().to_str().unwrap(), "-o", "pipe.scmesh", "-q"])
        .current_dir(dir.path())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sc-import starts");
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(&fifo).expect("read the FIFO"))
    };
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "sc-import did not finish writing the FIFO");
        std::thread::sleep(Duration::from_millis(20));
    };
    // (checked before joining: a reader of a replaced FIFO waits forever)
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    // a writer that never opened the FIFO would leave the reader blocked: open it once
    if !status.success() {
        let _ = std::fs::OpenOptions::new().write(true).open(&fifo);
    }
    let bytes = reader.join().unwrap();
    assert!(status.success(), "sc-import failed");
    let f = splinecontact::format::stage::StageFile::parse("pipe", &bytes, Some(("scmesh", 1))).expect("a whole scmesh came out");
    assert!(f.tail.is_none());
}

/// An output path that is a directory is refused before anything is written.
#[test]
fn an_output_that_is_a_directory_is_refused() {
    let dir = tempdir();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let o = run("sc-import", &[box_msh().to_str().unwrap(), "-o", "out"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(IO), "{err}");
    assert!(err.contains("out: cannot write") && err.contains("is a directory"), "{err}");
    assert!(dir.path().join("out").is_dir());
    assert_eq!(std::fs::read_dir(dir.path().join("out")).unwrap().count(), 0);
}

/// A missing folder, and a read-only one, give an error naming the path. Root
/// writes into a mode-555 folder, so under root (CI) the read-only half runs the
/// stage as `nobody` through `setpriv` (util-linux), the user a read-only folder is
/// meant to stop.
#[test]
fn a_missing_or_read_only_folder_is_a_clear_error() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempdir();
    let o = run("sc-import", &[box_msh().to_str().unwrap(), "-o", "nowhere/box.scmesh"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(IO), "{err}");
    assert!(err.contains("nowhere/box.scmesh: cannot create its temporary file") && err.contains("No such file or directory"), "{err}");

    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let root = std::fs::write(ro.join("probe"), b"x").is_ok();
    let o = if root {
        let _ = std::fs::remove_file(ro.join("probe"));
        // nobody must reach the folder, the input and the binary (the repository's
        // folders are world-readable, the temporary directory is not)
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
        Command::new("setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups", env!("CARGO_BIN_EXE_sc-import")])
            .args([box_msh().to_str().unwrap(), "-o", "ro/box.scmesh"])
            .current_dir(dir.path())
            .output()
            .expect("setpriv (util-linux) runs the read-only case as nobody when the tests run as root")
    } else {
        run("sc-import", &[box_msh().to_str().unwrap(), "-o", "ro/box.scmesh"], dir.path())
    };
    let err = stderr(&o);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(o.status.code(), Some(IO), "{err}");
    assert!(err.contains("ro/box.scmesh: cannot create its temporary file") && err.contains("Permission denied"), "{err}");
    assert_eq!(std::fs::read_dir(&ro).unwrap().count(), 0);
}

/// A symbolic link to a regular file stays a link; the file it points to is replaced.
#[test]
fn a_symbolic_link_to_a_file_is_kept() {
    let dir = tempdir();
    std::fs::write(dir.path().join("real.scmesh"), b"old").unwrap();
    std::os::unix::fs::symlink("real.scmesh", dir.path().join("link.scmesh")).unwrap();
    let o = run("sc-import", &[box_msh().to_str().unwrap(), "-o", "link.scmesh", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(dir.path().join("link.scmesh")).unwrap().file_type().is_symlink());
    let bytes = std::fs::read(dir.path().join("real.scmesh")).unwrap();
    assert!(bytes.starts_with(b"splinecontact scmesh"));
}
