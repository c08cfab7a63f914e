//! One pipeline at a time per output folder.
//!
//! Every stage file is written whole (a temporary renamed onto it), but two
//! pipelines writing the same outputs at once would still interleave: one's export
//! reading the other's half-finished results, a `.pvd` series listing the other's
//! files. So `sc-pipeline` takes each folder it writes into before its first write
//! there, with a lock file `<folder>/.sc-pipeline.lock` holding its process id and
//! pipeline, and removes it when it ends. A second pipeline that wants the folder
//! refuses with a message naming the first; a lock whose process no longer runs
//! (a killed pipeline; Linux: no `/proc/<pid>`) is taken over.
//!
//! The lock file is made complete first (a temporary with the contents) and then
//! hard-linked into place, which fails if a lock exists: the lock either does not
//! exist or names its owner, never half-written.

use std::fs;
use std::path::{Path, PathBuf};

/// The lock file's name inside the folder.
pub const LOCK_NAME: &str = ".sc-pipeline.lock";

/// Why a folder could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    #[error("{folder}: another sc-pipeline (process {pid}, running {owner}) is writing into this folder; wait for it to end, or give this pipeline other output paths (the lock, {lock}, of a pipeline that was killed is taken over)")]
    Busy { folder: String, pid: u32, owner: String, lock: String },
    #[error("{folder}: cannot lock the folder for writing: {source}")]
    Io { folder: String, source: std::io::Error },
}

/// A held folder; dropping it removes the lock file.
#[derive(Debug)]
pub struct FolderLock {
    /// The folder, canonical.
    pub folder: PathBuf,
    lock: PathBuf,
}

/// The process id and pipeline a lock file names.
fn read_owner(lock: &Path) -> Option<(u32, String)> {
    let text = fs::read_to_string(lock).ok()?;
    let mut lines = text.lines();
    let pid = lines.next()?.strip_prefix("pid ")?.trim().parse().ok()?;
    let owner = lines.next().and_then(|l| l.strip_prefix("pipeline ")).unwrap_or("?").to_string();
    Some((pid, owner))
}

fn alive(pid: u32) -> bool {
    // where /proc is missing (not Linux), every lock counts as alive: never taken over
    !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{pid}")).exists()
}

impl FolderLock {
    /// Take `folder` (which exists) for the pipeline `owner`.
    pub fn acquire(folder: &Path, owner: &str) -> Result<Self, LockError> {
        let shown = folder.display().to_string();
        let io = |source| LockError::Io { folder: shown.clone(), source };
        let folder = fs::canonicalize(folder).map_err(io)?;
        let lock = folder.join(LOCK_NAME);
        let me = std::process::id();
        let tmp = folder.join(format!("{LOCK_NAME}.{me}.tmp"));
        fs::write(&tmp, format!("pid {me}\npipeline {owner}\n")).map_err(io)?;
        let result = (|| {
            for _ in 0..3 {
                match fs::hard_link(&tmp, &lock) {
                    Ok(()) => return Ok(()),
                    Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                    Err(e) => return Err(io(e)),
                }
                match read_owner(&lock) {
                    Some((pid, owner)) if pid != me && alive(pid) => {
                        return Err(LockError::Busy { folder: shown.clone(), pid, owner, lock: lock.display().to_string() })
                    }
                    // a stale lock: claim it by renaming (only one claimant wins), check
                    // that what was claimed is still stale, then remove it
                    _ => {
                        let claimed = folder.join(format!("{LOCK_NAME}.{me}.stale"));
                        if fs::rename(&lock, &claimed).is_ok() {
                            match read_owner(&claimed) {
                                Some((pid, owner)) if pid != me && alive(pid) => {
                                    // a live lock taken between our read and our rename: give it back
                                    let _ = fs::hard_link(&claimed, &lock);
                                    let _ = fs::remove_file(&claimed);
                                    return Err(LockError::Busy { folder: shown.clone(), pid, owner, lock: lock.display().to_string() });
                                }
                                _ => {
                                    let _ = fs::remove_file(&claimed);
                                }
                            }
                        }
                    }
                }
            }
            Err(io(std::io::Error::other("the lock kept changing hands")))
        })();
        let _ = fs::remove_file(&tmp);
        result.map(|()| Self { folder, lock })
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        if read_owner(&self.lock).is_some_and(|(pid, _)| pid == std::process::id()) {
            let _ = fs::remove_file(&self.lock);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_folder_is_refused_and_freed_on_drop() {
        let dir = tempfile::tempdir().unwrap();
        let a = FolderLock::acquire(dir.path(), "a.yaml").unwrap();
        // this process again (a nested run): its own lock counts as stale, so fake
        // another live owner: pid 1 always runs
        fs::write(dir.path().join(LOCK_NAME), "pid 1\npipeline other.yaml\n").unwrap();
        let e = FolderLock::acquire(dir.path(), "b.yaml").unwrap_err().to_string();
        assert!(e.contains("another sc-pipeline (process 1, running other.yaml)"), "{e}");
        // a's drop leaves a lock it does not own alone
        drop(a);
        assert!(dir.path().join(LOCK_NAME).exists());
        fs::remove_file(dir.path().join(LOCK_NAME)).unwrap();
        let b = FolderLock::acquire(dir.path(), "b.yaml").unwrap();
        drop(b);
        assert!(!dir.path().join(LOCK_NAME).exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0, "temporaries left");
    }

    #[test]
    fn a_lock_of_a_process_that_is_gone_is_taken_over() {
        if !Path::new("/proc/self").exists() {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        fs::write(dir.path().join(LOCK_NAME), format!("pid {dead}\npipeline killed.yaml\n")).unwrap();
        let l = FolderLock::acquire(dir.path(), "b.yaml").unwrap();
        assert_eq!(read_owner(&dir.path().join(LOCK_NAME)).unwrap(), (std::process::id(), "b.yaml".to_string()));
        drop(l);
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
