//! Output directories as transactions.
//!
//! A command that writes a result set (run, map, report, bench, validate, study) opens an
//! [`OutputDir`] on its target directory, writes every file into [`OutputDir::path`] (a
//! temporary directory beside the target) and calls [`OutputDir::commit`], which swaps the new
//! directory in (one `renameat2(RENAME_EXCHANGE)` on Linux, else two renames) and removes the
//! old one. So the target holds either the complete previous result set or the complete new one,
//! never a mix, and a failure before the commit leaves the previous result untouched.
//!
//! - **Lock**: `.<name>.geartherm-lock` beside the target, held with an exclusive advisory lock
//!   (`flock`) for the whole transaction; a second writer into the same target is refused with
//!   a message naming the holder's PID. The kernel drops the lock when its holder dies, so a
//!   killed run never blocks the next one.
//! - **Stale temporaries**: `.<name>.geartherm-tmp-*` and `.<name>.geartherm-old-*` left by a
//!   killed writer are removed by the next writer into the same target (which holds the lock,
//!   so they cannot belong to a live writer). A previous result caught between the two renames
//!   of the fallback swap is restored.
//! - **Ownership**: a target is replaced only if it is new, empty, marked by a previous commit
//!   (`.geartherm-output`) or holds nothing but files geartherm writes; a directory holding
//!   anything else (`--out .`, `--out ~`) is refused rather than swapped away.
//! - **Mode**: files and directories are created with the usual mode (0666 / 0777 less the
//!   umask), not the 0600 of temporary files.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// Marker written into every committed output directory.
pub const MARKER: &str = ".geartherm-output";

/// Names geartherm wrote before the marker existed: a directory holding only these (and their
/// hidden temporaries) is recognised as an earlier geartherm output.
const KNOWN_OUTPUTS: &[&str] = &[
    "timeseries.csv",
    "summary.json",
    "temperatures.png",
    "losses.png",
    "energy.png",
    "efficiency.png",
    "report.md",
    "map.csv",
    "map.json",
    "map_efficiency.png",
    "map_total_loss.png",
    "map_oil_temp.png",
    "bench.csv",
    "bench.json",
    "work_precision.png",
];

/// Why an output directory could not be opened or committed.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Another process holds the lock.
    #[error(
        "{}: another geartherm{} is writing this directory (lock {}); wait for it to finish or choose another --out",
        target.display(),
        holder.as_deref().map(|p| format!(" (pid {p})")).unwrap_or_default(),
        lock.display()
    )]
    Busy {
        /// The target directory.
        target: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// PID recorded in the lock file.
        holder: Option<String>,
    },
    /// The target holds files geartherm did not write.
    #[error(
        "{}: holds files geartherm did not write ({}); it would be replaced as a whole: choose a new or empty directory",
        target.display(),
        names.join(", ")
    )]
    Foreign {
        /// The target directory.
        target: PathBuf,
        /// Up to five foreign entries.
        names: Vec<String>,
    },
    /// The target exists and is not a directory.
    #[error("{}: exists and is not a directory", target.display())]
    NotADirectory {
        /// The target.
        target: PathBuf,
    },
    /// An I/O error on `path`.
    #[error("{}: {source}", path.display())]
    Io {
        /// Path concerned.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// An exclusive lock on a target directory, released (and its file removed) on drop.
#[derive(Debug)]
pub struct DirLock {
    file: File,
    path: PathBuf,
}

impl DirLock {
    fn acquire(target: &Path, lock: PathBuf) -> Result<Self, OutputError> {
        // A lock file may be unlinked by its previous holder between our open and our lock:
        // retry until the locked file is the one the path names.
        for _ in 0..100 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&lock)
                .map_err(io_at(&lock))?;
            match try_lock(&file) {
                Ok(true) => {}
                Ok(false) => {
                    let mut s = String::new();
                    let _ = file.read_to_string(&mut s);
                    let holder = s.trim().parse::<u32>().ok().map(|p| p.to_string());
                    return Err(OutputError::Busy {
                        target: target.to_path_buf(),
                        lock,
                        holder,
                    });
                }
                Err(e) => return Err(io_at(&lock)(e)),
            }
            if same_file(&file, &lock) {
                let _ = file.set_len(0);
                let _ = file.rewind();
                let _ = write!(file, "{}", std::process::id());
                return Ok(DirLock { file, path: lock });
            }
        }
        Err(io_at(&lock)(std::io::Error::other(
            "lock file keeps being replaced",
        )))
    }
}

/// Exclusive, non-blocking `flock`: Ok(false) when another process holds it. (std's
/// `File::try_lock` needs Rust 1.89; the crate keeps 1.80.)
#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a file descriptor owned by `file` for the duration of the call.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    if e.kind() == std::io::ErrorKind::WouldBlock {
        Ok(false)
    } else {
        Err(e)
    }
}

#[cfg(unix)]
fn unlock(file: &File) {
    use std::os::unix::io::AsRawFd;
    // SAFETY: as in `try_lock`.
    unsafe {
        libc::flock(file.as_raw_fd(), libc::LOCK_UN);
    }
}

/// Non-Unix systems: no advisory lock (the transaction itself still holds).
#[cfg(not(unix))]
fn try_lock(_file: &File) -> std::io::Result<bool> {
    Ok(true)
}

#[cfg(not(unix))]
fn unlock(_file: &File) {}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // Unlink while still holding the lock; a waiter that opened the old inode re-checks.
        let _ = fs::remove_file(&self.path);
        unlock(&self.file);
    }
}

/// `target` resolved, its parent directory (created) and its file name.
fn place(target: &Path) -> Result<(PathBuf, PathBuf, String), OutputError> {
    let target = resolve(target)?;
    // `Path::new("out").parent()` is `Some("")`: a bare name lives in the working directory.
    let parent = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    let name = target
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .ok_or_else(|| OutputError::NotADirectory {
            target: target.clone(),
        })?;
    fs::create_dir_all(&parent).map_err(io_at(&parent))?;
    Ok((target, parent, name))
}

/// Lock `target` for a writer that fills it in place rather than by a swap (a resumable study
/// appends to its journal): `part` names what is locked, so writers of different parts (the
/// shards of one study) run side by side while a second writer of the same part is refused with
/// [`OutputError::Busy`], naming the holder's pid.
pub fn lock_in_place(target: &Path, part: &str) -> Result<DirLock, OutputError> {
    let (target, parent, name) = place(target)?;
    DirLock::acquire(&target, parent.join(format!(".{name}.{part}.geartherm-lock")))
}

/// A result set being written: files go into [`OutputDir::path`]; [`OutputDir::commit`] swaps
/// it into the target. Dropped without a commit, it removes its temporary directory and leaves
/// the target as it was.
#[derive(Debug)]
pub struct OutputDir {
    target: PathBuf,
    staging: PathBuf,
    parent: PathBuf,
    name: String,
    committed: bool,
    _lock: DirLock,
}

impl OutputDir {
    /// Lock `target`, clean stale temporaries of earlier killed writers, check that `target`
    /// may be replaced, and create the temporary directory beside it.
    pub fn begin(target: &Path) -> Result<Self, OutputError> {
        let (target, parent, name) = place(target)?;
        let lock = DirLock::acquire(&target, parent.join(format!(".{name}.geartherm-lock")))?;
        clean_stale(&parent, &name, &target)?;
        check_replaceable(&target)?;
        let staging = parent.join(format!(
            ".{name}.geartherm-tmp-{}-{}",
            std::process::id(),
            unique()
        ));
        fs::create_dir(&staging).map_err(io_at(&staging))?;
        Ok(OutputDir {
            target,
            staging,
            parent,
            name,
            committed: false,
            _lock: lock,
        })
    }

    /// The temporary directory to write into.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The target directory (as resolved).
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Write one file (usual mode) into the temporary directory; returns its final path.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf, OutputError> {
        let p = self.staging.join(name);
        let mut f = File::create(&p).map_err(io_at(&p))?;
        f.write_all(bytes).map_err(io_at(&p))?;
        Ok(self.target.join(name))
    }

    /// Copy `names` that exist in the current target into the temporary directory (a `report`
    /// re-renders a directory: its inputs are carried into the new result set).
    pub fn carry_over(&self, names: &[&str]) -> Result<(), OutputError> {
        for n in names {
            let src = self.target.join(n);
            if src.is_file() {
                let dst = self.staging.join(n);
                if fs::hard_link(&src, &dst).is_err() {
                    fs::copy(&src, &dst).map_err(io_at(&src))?;
                }
            }
        }
        Ok(())
    }

    /// Swap the new result set in. On error the target keeps the previous result.
    pub fn commit(mut self) -> Result<PathBuf, OutputError> {
        self.write(
            MARKER,
            b"written by geartherm; this directory is replaced as a whole by the next run into it\n",
        )?;
        sync_dir_files(&self.staging);
        if self.target.exists() {
            if !exchange(&self.staging, &self.target) {
                let old = self.parent.join(format!(
                    ".{}.geartherm-old-{}-{}",
                    self.name,
                    std::process::id(),
                    unique()
                ));
                fs::rename(&self.target, &old).map_err(io_at(&self.target))?;
                if let Err(e) = fs::rename(&self.staging, &self.target) {
                    let _ = fs::rename(&old, &self.target);
                    return Err(io_at(&self.target)(e));
                }
                self.staging = old;
            }
            // `staging` now names the previous result set.
            let _ = fs::remove_dir_all(&self.staging);
        } else {
            fs::rename(&self.staging, &self.target).map_err(io_at(&self.target))?;
        }
        self.committed = true;
        Ok(self.target.clone())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

/// Follow a symlinked target to the directory it names; keep relative paths relative.
fn resolve(target: &Path) -> Result<PathBuf, OutputError> {
    if target.as_os_str().is_empty() || target.file_name().is_none() {
        // `.`, `..`, `/`: name the directory itself.
        let abs = fs::canonicalize(target).map_err(io_at(target))?;
        return Ok(abs);
    }
    match fs::symlink_metadata(target) {
        Ok(m) if m.file_type().is_symlink() => fs::canonicalize(target).map_err(io_at(target)),
        _ => Ok(target.to_path_buf()),
    }
}

/// The path a user knows for `path`: a file in the temporary directory of a transaction on
/// `dir/name` (`dir/.name.geartherm-tmp-<pid>-<n>/file`) is named by its place in the target
/// (`dir/name/file`); the `./` [`OutputDir::begin`] puts before a bare name is left out again.
/// Other paths are returned as they are. For error messages.
pub fn user_path(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    let mut parts = path.components().peekable();
    while let Some(c) = parts.next() {
        let staged = |c: Option<&std::path::Component>| {
            c.and_then(|c| staging_target(c.as_os_str().to_str()?)).is_some()
        };
        match c {
            std::path::Component::CurDir if out.as_os_str().is_empty() && staged(parts.peek()) => {}
            c => match staging_target(c.as_os_str().to_str().unwrap_or("")) {
                Some(name) => out.push(name),
                None => out.push(c),
            },
        }
    }
    out
}

/// The target name of a transaction's temporary directory name `.name.geartherm-tmp-<pid>-<n>`.
fn staging_target(dir_name: &str) -> Option<&str> {
    let (name, tail) = dir_name.strip_prefix('.')?.rsplit_once(".geartherm-tmp-")?;
    let (pid, n) = tail.split_once('-')?;
    let numbers = pid.parse::<u32>().is_ok() && n.parse::<u128>().is_ok();
    (numbers && !name.is_empty()).then_some(name)
}

fn unique() -> u128 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos())
}

/// Remove temporaries of earlier writers into `target` (we hold its lock, so they are dead);
/// restore a previous result set a killed fallback swap left renamed away.
fn clean_stale(parent: &Path, name: &str, target: &Path) -> Result<(), OutputError> {
    let tmp = format!(".{name}.geartherm-tmp-");
    let old = format!(".{name}.geartherm-old-");
    let entries = fs::read_dir(parent).map_err(io_at(parent))?;
    for e in entries.flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        if n.starts_with(&old) && !target.exists() {
            let _ = fs::rename(e.path(), target);
        } else if n.starts_with(&tmp) || n.starts_with(&old) {
            let _ = fs::remove_dir_all(e.path());
        }
    }
    Ok(())
}

fn is_ours(name: &str) -> bool {
    name == MARKER
        || KNOWN_OUTPUTS.contains(&name)
        || KNOWN_OUTPUTS.iter().any(|k| name.starts_with(&format!(".{k}.")))
}

fn check_replaceable(target: &Path) -> Result<(), OutputError> {
    let meta = match fs::metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_at(target)(e)),
    };
    if !meta.is_dir() {
        return Err(OutputError::NotADirectory {
            target: target.to_path_buf(),
        });
    }
    let entries: Vec<String> = fs::read_dir(target)
        .map_err(io_at(target))?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if entries.iter().any(|n| n == MARKER) {
        return Ok(());
    }
    let foreign: Vec<String> = entries.into_iter().filter(|n| !is_ours(n)).take(5).collect();
    if foreign.is_empty() {
        Ok(())
    } else {
        Err(OutputError::Foreign {
            target: target.to_path_buf(),
            names: foreign,
        })
    }
}

fn sync_dir_files(dir: &Path) {
    if let Ok(entries) = fs::read_dir(dir) {
        for e in entries.flatten() {
            if let Ok(f) = File::open(e.path()) {
                let _ = f.sync_all();
            }
        }
    }
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// Atomically exchange two directories (Linux `renameat2(RENAME_EXCHANGE)`); false when the
/// system does not support it.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> bool {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let (Ok(ca), Ok(cb)) = (
        CString::new(a.as_os_str().as_bytes()),
        CString::new(b.as_os_str().as_bytes()),
    ) else {
        return false;
    };
    // SAFETY: both paths are valid NUL-terminated C strings that outlive the call.
    let r = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    r == 0
}

#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> bool {
    false
}

/// Write one file atomically: `bytes` go to a temporary file in `path`'s directory (which must
/// exist: nothing is created), renamed to `path` when complete. On error nothing is left.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".geartherm.")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Write `files` (name, contents) into `dir` file by file: each is written to a temporary file
/// (usual mode) in `dir` and all are renamed into place only when every one was written; other
/// files in `dir` stay. For a directory that is not replaced as a whole (`study` writes its
/// cases and journal beside `study.csv`); a result set uses [`replace_all_atomic`].
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> std::io::Result<Vec<PathBuf>> {
    fs::create_dir_all(dir)?;
    let mut temps = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let prefix = format!(".{name}.");
        let mut b = tempfile::Builder::new();
        b.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        b.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let mut tmp = b.tempfile_in(dir)?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        temps.push((tmp, dir.join(name)));
    }
    let mut out = Vec::with_capacity(temps.len());
    for (tmp, dest) in temps {
        tmp.persist(&dest).map_err(|e| e.error)?;
        out.push(dest);
    }
    Ok(out)
}

/// Write `files` (name, contents) into `dir` as one transaction ([`OutputDir`]): `dir` then
/// holds exactly these files (and the marker); on any error it keeps what it held.
pub fn replace_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> Result<Vec<PathBuf>, OutputError> {
    let out = OutputDir::begin(dir)?;
    let mut paths = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        paths.push(out.write(name, bytes)?);
    }
    out.commit()?;
    Ok(paths)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_of_a_transaction_is_named_by_its_place_in_the_target() {
        let cases = [
            ("./.rd.geartherm-tmp-12-345/summary.json", "rd/summary.json"),
            (
                "/tmp/.rd.geartherm-tmp-12-345/summary.json",
                "/tmp/rd/summary.json",
            ),
            ("../x/.a.b.geartherm-tmp-1-2/map.csv", "../x/a.b/map.csv"),
            // Not a transaction's directory: kept.
            (
                "./.rd.geartherm-tmp-x-2/summary.json",
                "./.rd.geartherm-tmp-x-2/summary.json",
            ),
            ("./rd/summary.json", "./rd/summary.json"),
            ("rd/summary.json", "rd/summary.json"),
        ];
        for (path, shown) in cases {
            assert_eq!(user_path(Path::new(path)), PathBuf::from(shown), "{path}");
        }
        // What `begin` makes is what `user_path` undoes.
        let d = tempfile::tempdir().unwrap();
        let out = OutputDir::begin(&d.path().join("run")).unwrap();
        assert_eq!(
            user_path(&out.path().join("summary.json")),
            d.path().join("run/summary.json")
        );
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_files_and_leaves_no_temporaries() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        let paths = replace_all_atomic(&sub, &[("a.txt", b"one"), ("b.txt", b"two")]).unwrap();
        assert_eq!(paths.len(), 2);
        assert_eq!(fs::read(sub.join("a.txt")).unwrap(), b"one");
        assert_eq!(names(&sub), [MARKER, "a.txt", "b.txt"]);
        assert_eq!(names(d.path()), ["run"], "nothing beside the target");
    }

    #[test]
    fn a_new_result_replaces_the_old_set_as_a_whole() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        replace_all_atomic(&sub, &[("a.txt", b"one"), ("b.txt", b"two")]).unwrap();
        replace_all_atomic(&sub, &[("a.txt", b"three")]).unwrap();
        assert_eq!(names(&sub), [MARKER, "a.txt"], "b.txt of the old set is gone");
        assert_eq!(fs::read(sub.join("a.txt")).unwrap(), b"three");
    }

    #[test]
    fn an_uncommitted_transaction_leaves_the_old_set() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        replace_all_atomic(&sub, &[("a.txt", b"one")]).unwrap();
        {
            let out = OutputDir::begin(&sub).unwrap();
            out.write("a.txt", b"half").unwrap();
        }
        assert_eq!(fs::read(sub.join("a.txt")).unwrap(), b"one");
        assert_eq!(names(d.path()), ["run"]);
    }

    #[test]
    fn a_second_writer_is_refused_while_the_first_holds_the_lock() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        let first = OutputDir::begin(&sub).unwrap();
        let err = OutputDir::begin(&sub).unwrap_err();
        assert!(matches!(err, OutputError::Busy { .. }), "{err}");
        assert!(err.to_string().contains("another geartherm"), "{err}");
        drop(first);
        OutputDir::begin(&sub).unwrap().commit().unwrap();
    }

    #[test]
    fn stale_temporaries_of_a_dead_writer_are_removed() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        replace_all_atomic(&sub, &[("a.txt", b"one")]).unwrap();
        let stale = d.path().join(".run.geartherm-tmp-1-2");
        fs::create_dir(&stale).unwrap();
        fs::write(stale.join("timeseries.csv"), b"x").unwrap();
        replace_all_atomic(&sub, &[("a.txt", b"two")]).unwrap();
        assert_eq!(names(d.path()), ["run"]);
    }

    #[test]
    fn a_result_renamed_away_by_a_killed_swap_is_restored() {
        let d = tempfile::tempdir().unwrap();
        let old = d.path().join(".run.geartherm-old-1-2");
        fs::create_dir(&old).unwrap();
        fs::write(old.join("summary.json"), b"one").unwrap();
        let out = OutputDir::begin(&d.path().join("run")).unwrap();
        assert_eq!(fs::read(d.path().join("run/summary.json")).unwrap(), b"one");
        drop(out);
    }

    #[test]
    fn a_directory_with_foreign_files_is_not_swapped_away() {
        let d = tempfile::tempdir().unwrap();
        fs::write(d.path().join("thesis.tex"), b"precious").unwrap();
        let err = OutputDir::begin(d.path()).unwrap_err();
        assert!(matches!(err, OutputError::Foreign { .. }), "{err}");
        assert!(err.to_string().contains("thesis.tex"), "{err}");
        assert_eq!(fs::read(d.path().join("thesis.tex")).unwrap(), b"precious");
    }

    #[test]
    fn a_legacy_output_directory_is_accepted() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        fs::create_dir(&sub).unwrap();
        fs::write(sub.join("summary.json"), b"{}").unwrap();
        fs::write(sub.join(".timeseries.csv.abc.tmp"), b"partial").unwrap();
        replace_all_atomic(&sub, &[("summary.json", b"{\"a\":1}")]).unwrap();
        assert_eq!(names(&sub), [MARKER, "summary.json"]);
    }

    #[cfg(unix)]
    #[test]
    fn files_get_the_usual_mode_not_0600() {
        use std::os::unix::fs::PermissionsExt;
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        replace_all_atomic(&sub, &[("a.txt", b"one")]).unwrap();
        let mode = fs::metadata(sub.join("a.txt")).unwrap().permissions().mode() & 0o777;
        let dmode = fs::metadata(&sub).unwrap().permissions().mode() & 0o777;
        // The test process's umask is at most 0o077 in any sane environment; a 0600 file or a
        // 0700 directory means the mode was forced, not derived from the umask.
        let umask = current_umask();
        assert_eq!(mode, 0o666 & !umask, "file mode {mode:o}, umask {umask:o}");
        assert_eq!(dmode, 0o777 & !umask, "dir mode {dmode:o}, umask {umask:o}");
    }

    #[cfg(unix)]
    fn current_umask() -> u32 {
        use std::os::unix::fs::PermissionsExt;
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("probe");
        File::create(&p).unwrap();
        0o666 & !(fs::metadata(&p).unwrap().permissions().mode() & 0o777)
    }
}
