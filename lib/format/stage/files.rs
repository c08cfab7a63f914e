//! The file system side of every format: reading a file or standard input,
//! writing an output so that a failure never leaves a half-written file, and
//! resolving a path named in a file against that file's folder.

use std::fs;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use super::error::StageError;

/// Read a whole file, or standard input when the path is `-`.
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    if path.as_os_str() == "-" {
        let mut v = Vec::new();
        io::stdin().lock().read_to_end(&mut v)?;
        Ok(v)
    } else {
        fs::read(path)
    }
}

/// Write `bytes` to `path`: a regular file (or a new one) atomically, anything
/// else in place; see [`write_atomic_with`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), StageError> {
    write_replacing(path, true, 0, |w| w.write_all(bytes))
}

/// [`write_atomic`] without the `fsync` before the rename, for a file derived from
/// another that is synced (the solver's CSV histories, which the results file holds
/// and a restart rewrites): a killed process still leaves the old file or the new
/// one, whole; a power loss may leave the new one empty. Saves an `fdatasync`
/// (0.3–0.8 ms on the reference machine) per rewrite.
pub fn write_atomic_unsynced(path: &Path, bytes: &[u8]) -> Result<(), StageError> {
    prepare_unsynced(path, bytes)?.commit()
}

/// A replacement of a regular file made ready but not yet in place: `bytes` are in
/// the temporary `.<name>.<pid>.tmp` beside the target, their write-back started;
/// [`Prepared::commit`] renames it onto the target, and dropping it uncommitted
/// removes the temporary (the target untouched). The solver prepares its CSV
/// histories on a thread of its own while the results file is synced, and commits
/// them once it is: the two writes overlap and the histories still never get ahead
/// of the results on disk.
#[must_use = "a prepared replacement is removed unless committed"]
pub struct Prepared {
    /// (temporary, target, the path as given, for messages); `None`: written in
    /// place already (standard output, a device, a FIFO)
    pending: Option<(PathBuf, PathBuf, String)>,
}

impl Prepared {
    /// Rename the temporary onto its target (an error names the path and removes
    /// the temporary).
    pub fn commit(mut self) -> Result<(), StageError> {
        let Some((tmp, target, shown)) = self.pending.take() else { return Ok(()) };
        fs::rename(&tmp, &target).map_err(|e| {
            let _ = fs::remove_file(&tmp);
            StageError::Io { path: shown, action: "rename the temporary file onto", source: e }
        })
    }
}

impl Drop for Prepared {
    fn drop(&mut self) {
        if let Some((tmp, _, _)) = self.pending.take() {
            let _ = fs::remove_file(tmp);
        }
    }
}

/// [`write_atomic_unsynced`] up to the rename: a [`Prepared`] replacement. Standard
/// output, a device or a FIFO are written in place at once (nothing to commit).
/// The temporary's write-back is started (Linux `sync_file_range`, not waited
/// for), so that the rename onto an existing file does not start it itself (ext4's
/// `auto_da_alloc` flushes a file renamed over another: 1.3 ms on the reference
/// machine, inside the rename).
pub fn prepare_unsynced(path: &Path, bytes: &[u8]) -> Result<Prepared, StageError> {
    prepare(path, false, 0, |w| w.write_all(bytes))
}

/// Ask the kernel to start writing `file`'s dirty pages out, without waiting (a
/// hint: an error changes nothing and is ignored).
fn start_write_back(file: &fs::File) {
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        // SAFETY: a valid open descriptor; the call reads no memory of ours
        let _ = unsafe { libc::sync_file_range(file.as_raw_fd(), 0, 0, libc::SYNC_FILE_RANGE_WRITE) };
    }
    #[cfg(not(target_os = "linux"))]
    let _ = file;
}

/// Where [`write_atomic_with`] puts its bytes, decided by what `path` names now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputKind {
    /// `-`: standard output.
    Stdout,
    /// A regular file, or nothing yet: a temporary file beside it, renamed onto
    /// it (`target` is the path itself, or the file a symbolic link points to, so
    /// that the link survives).
    Regular { target: PathBuf },
    /// A device, a FIFO or a socket: written in place. Renaming onto it would
    /// replace the device node with a regular file.
    Special,
}

/// What `path` names, or a clear error: a directory is no output, and a path that
/// cannot be inspected (a missing parent folder, no permission) is refused before
/// anything is produced.
pub fn output_kind(path: &Path) -> Result<OutputKind, StageError> {
    let shown = || path.display().to_string();
    if path.as_os_str() == "-" {
        return Ok(OutputKind::Stdout);
    }
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(StageError::Io {
            path: shown(),
            action: "write",
            source: io::Error::new(io::ErrorKind::IsADirectory, "it is a directory (give a file name inside it)"),
        }),
        Ok(m) if m.is_file() => {
            let target = if fs::symlink_metadata(path).is_ok_and(|l| l.file_type().is_symlink()) {
                fs::canonicalize(path).map_err(|source| StageError::Io { path: shown(), action: "follow the symbolic link", source })?
            } else {
                path.to_path_buf()
            };
            Ok(OutputKind::Regular { target })
        }
        Ok(_) => Ok(OutputKind::Special),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(OutputKind::Regular { target: path.to_path_buf() }),
        Err(source) => Err(StageError::Io { path: shown(), action: "inspect the output path", source }),
    }
}

/// Write what `f` produces to `path`, so that a failure never leaves a half-written
/// regular file and never replaces what is not a regular file:
/// - a regular file, or a path that does not exist yet: into a temporary
///   `.<name>.<pid>.tmp` in the same folder, `fsync`ed, then renamed onto the
///   target (an existing file survives any failure; the temporary is removed);
/// - a device, a FIFO or a socket: opened and written in place (never created,
///   never renamed over); a write error (a full device: ENOSPC) is returned;
/// - `-`: standard output;
/// - a directory: an error, before `f` runs.
pub fn write_atomic_with(path: &Path, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), StageError> {
    write_replacing(path, true, WRITE_BUFFER, f)
}

/// The write buffer of [`write_atomic_with`]'s producers, which write piece by piece.
const WRITE_BUFFER: usize = 1 << 20;

/// [`write_atomic_with`], the temporary `fsync`ed before the rename when `sync`,
/// through a buffer of `buffer` bytes (0: bytes already whole go straight to the
/// file, without a buffer to allocate and touch).
fn write_replacing(path: &Path, sync: bool, buffer: usize, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), StageError> {
    prepare(path, sync, buffer, f)?.commit()
}

/// [`write_replacing`] up to the rename: standard output, a device or a FIFO written
/// in place at once (nothing left to commit); a regular file's bytes in its
/// temporary, `fsync`ed when `sync`, else their write-back started.
fn prepare(path: &Path, sync: bool, buffer: usize, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<Prepared, StageError> {
    let shown = path.display().to_string();
    let io_err = |action: &'static str| {
        let shown = shown.clone();
        move |source| StageError::Io { path: shown, action, source }
    };
    let target = match output_kind(path)? {
        OutputKind::Stdout => {
            let mut buf = Vec::new();
            f(&mut buf).map_err(io_err("produce"))?;
            let mut out = io::stdout().lock();
            out.write_all(&buf).and_then(|_| out.flush()).map_err(io_err("write to standard output"))?;
            return Ok(Prepared { pending: None });
        }
        OutputKind::Special => {
            let file = fs::OpenOptions::new().write(true).open(path).map_err(io_err("open for writing"))?;
            let mut w = io::BufWriter::with_capacity(buffer, file);
            f(&mut w).and_then(|_| w.flush()).map_err(io_err("write"))?;
            return Ok(Prepared { pending: None });
        }
        OutputKind::Regular { target } => target,
    };
    remove_stale_temporaries(&target);
    let tmp = temp_path(&target);
    let file = fs::File::create(&tmp).map_err(io_err("create its temporary file in the same folder"))?;
    // from here on the temporary is the Prepared's: an error drops (removes) it
    let prepared = Prepared { pending: Some((tmp, target, shown.clone())) };
    let mut w = io::BufWriter::with_capacity(buffer, file);
    f(&mut w)
        .and_then(|_| w.into_inner().map_err(|e| e.into_error()))
        .and_then(|file| {
            if sync {
                file.sync_data()
            } else {
                start_write_back(&file);
                Ok(())
            }
        })
        .map_err(io_err("write"))?;
    Ok(prepared)
}

/// Remove the temporaries of `target` (`.name.<pid>.tmp`) that a killed writer left:
/// those whose process no longer runs (Linux: no `/proc/<pid>`). A live writer's
/// temporary, another program's file, or anything elsewhere is never touched.
fn remove_stale_temporaries(target: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Some(name) = target.file_name().map(|n| n.to_string_lossy().into_owned()) else { return };
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let prefix = format!(".{name}.");
    let Ok(entries) = fs::read_dir(&dir) else { return };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let pid = file.strip_prefix(&prefix).and_then(|r| r.strip_suffix(".tmp")).and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid {
            if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
                let _ = fs::remove_file(e.path());
            }
        }
    }
}

/// `dir/.name.<pid>.tmp` beside the target (same file system, so rename is atomic).
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
    let tmp = format!(".{name}.{}.tmp", std::process::id());
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// Resolve a path named in a file (a pipeline YAML) against that file's folder
/// (absolute paths and `-` are kept as they are).
pub fn resolve(base: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() || p.as_os_str() == "-" {
        p.to_path_buf()
    } else {
        base.join(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prepared replacement leaves the target as it was until committed; dropped
    /// uncommitted, it leaves no temporary behind.
    #[test]
    fn a_prepared_replacement_touches_the_target_only_when_committed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("h.forces.csv");
        write_atomic(&target, b"old\n").unwrap();
        let names = || -> Vec<String> {
            let mut v: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
            v.sort();
            v
        };
        let dropped = prepare_unsynced(&target, b"dropped\n").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"old\n");
        assert_eq!(names().len(), 2, "the temporary is beside the target");
        drop(dropped);
        assert_eq!(names(), ["h.forces.csv"]);
        assert_eq!(fs::read(&target).unwrap(), b"old\n");
        let kept = prepare_unsynced(&target, b"new\n").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"old\n");
        kept.commit().unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new\n");
        assert_eq!(names(), ["h.forces.csv"]);
    }

    /// Synced or not, a write replaces the target whole and leaves no temporary;
    /// a directory is refused before anything is written.
    #[test]
    fn an_unsynced_write_replaces_the_target_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("h.convergence.csv");
        write_atomic(&target, b"old\n").unwrap();
        write_atomic_unsynced(&target, b"iteration,residual\n0,1\n").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"iteration,residual\n0,1\n");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names, ["h.convergence.csv"]);
        let err = write_atomic_unsynced(dir.path(), b"x").unwrap_err().to_string();
        assert!(err.contains(&dir.path().display().to_string()), "{err}");
    }
}
