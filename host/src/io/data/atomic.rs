//! All-or-nothing writing of a command's outputs, rolled back on failure or interruption.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::DataError;

/// Writes bytes to `path` through a temporary file in the same directory and a rename, so a
/// reader never sees a half-written file (one file of [`write_all_atomic`], under the same
/// interruption rules).
///
/// # Errors
/// [`DataError::Io`] when the file cannot be written or renamed; [`DataError::Interrupted`]
/// when the process was interrupted (nothing written).
///
/// ```
/// use yawcast::io::data::write_atomic;
/// let p = std::env::temp_dir().join(format!("yawcast-doc-one-{}.txt", std::process::id()));
/// write_atomic(&p, b"42").unwrap();
/// assert_eq!(std::fs::read(&p).unwrap(), b"42");
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), DataError> {
    OUTPUTS.write_all_refs(&[(path, bytes)], &mut |from, to| std::fs::rename(from, to))
}

/// Writes several files as one: every file goes to a temporary file beside its destination
/// first, and only when all of them are written are they renamed into place. A destination
/// that already exists is kept as a backup (a hard link, or a copy where links are not
/// possible) until every rename has succeeded: when a write or a rename fails, the files
/// already renamed are removed, the backups put back byte for byte, every temporary file and
/// every directory created for the outputs removed. A command's outputs appear all together
/// or not at all.
///
/// The writes of a process are serialised with [`AtomicWriter::interrupt`] on the shared
/// [`OUTPUTS`]: a signal handler calling it waits for a write in progress to finish or to
/// roll back.
///
/// # Errors
/// [`DataError::Io`] naming the first file that could not be written (or renamed), or two
/// outputs with one destination; [`DataError::Interrupted`] when the process was interrupted
/// before or during the renames (then nothing was written).
///
/// ```
/// use yawcast::io::data::write_all_atomic;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-all-{}", std::process::id()));
/// let ok = [(dir.join("a.txt"), b"a".to_vec()), (dir.join("b.txt"), b"b".to_vec())];
/// write_all_atomic(&ok).unwrap();
/// assert_eq!(std::fs::read(dir.join("b.txt")).unwrap(), b"b");
/// // A destination that cannot be written (a directory stands there): nothing else appears.
/// std::fs::create_dir_all(dir.join("c.txt")).unwrap();
/// let bad = [(dir.join("new.txt"), b"n".to_vec()), (dir.join("c.txt"), b"c".to_vec())];
/// assert!(write_all_atomic(&bad).is_err());
/// assert!(!dir.join("new.txt").exists());
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> Result<(), DataError> {
    write_all_atomic_with(files, &mut |from, to| std::fs::rename(from, to))
}

/// [`write_all_atomic`] with the rename of each temporary file onto its destination done by
/// `rename(temporary, destination)`, called once per file in order (fault injection: a
/// rename that fails shows the roll-back; backups are made and restored without it).
///
/// # Errors
/// As [`write_all_atomic`]; an error of `rename` is reported naming its destination.
///
/// ```
/// use yawcast::io::data::write_all_atomic_with;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-with-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("b.txt"), b"old").unwrap();
/// let files = [(dir.join("a.txt"), b"a".to_vec()), (dir.join("b.txt"), b"b".to_vec())];
/// let mut n = 0;
/// let e = write_all_atomic_with(&files, &mut |from, to| {
///     n += 1;
///     if n == 2 { return Err(std::io::Error::other("disk full")); }
///     std::fs::rename(from, to)
/// })
/// .unwrap_err();
/// assert!(e.to_string().contains("b.txt: disk full"), "{e}");
/// assert!(!dir.join("a.txt").exists()); // renamed, then taken back
/// assert_eq!(std::fs::read(dir.join("b.txt")).unwrap(), b"old");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_all_atomic_with(
    files: &[(PathBuf, Vec<u8>)],
    rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
) -> Result<(), DataError> {
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    OUTPUTS.write_all_refs(&refs, rename)
}

/// Files to write together: each destination with its bytes.
pub type OutputFiles = Vec<(PathBuf, Vec<u8>)>;

/// The writer every output of the process goes through ([`write_atomic`],
/// [`write_all_atomic`]).
pub static OUTPUTS: AtomicWriter = AtomicWriter::new();

/// All-or-nothing writes serialised with interruption: one write at a time holds the lock
/// from its first temporary file to its last rename (or roll-back); [`AtomicWriter::interrupt`]
/// marks the writer interrupted and waits for that lock, so a signal handler that calls it
/// and then exits never leaves a temporary file, a backup or a part of a command's outputs.
#[derive(Debug)]
pub struct AtomicWriter {
    lock: std::sync::Mutex<()>,
    signal: std::sync::atomic::AtomicI32,
}

impl Default for AtomicWriter {
    fn default() -> Self {
        AtomicWriter::new()
    }
}

impl AtomicWriter {
    /// A writer not interrupted.
    ///
    /// ```
    /// let w = yawcast::io::data::AtomicWriter::new();
    /// assert_eq!(w.interrupted(), None);
    /// ```
    pub const fn new() -> Self {
        AtomicWriter {
            lock: std::sync::Mutex::new(()),
            signal: std::sync::atomic::AtomicI32::new(0),
        }
    }

    /// The signal the writer was interrupted by, if any.
    ///
    /// ```
    /// let w = yawcast::io::data::AtomicWriter::new();
    /// drop(w.interrupt(2));
    /// assert_eq!(w.interrupted(), Some(2));
    /// ```
    pub fn interrupted(&self) -> Option<i32> {
        match self.signal.load(std::sync::atomic::Ordering::SeqCst) {
            0 => None,
            s => Some(s),
        }
    }

    /// Marks the writer interrupted by `signal` (non-zero) and waits until no write is in
    /// progress: a write that has not reached its renames, or is between two of them, rolls
    /// back; one past its last rename finishes. While the returned guard is held no write
    /// starts, and every later write fails with [`DataError::Interrupted`] without touching
    /// a file.
    ///
    /// ```
    /// use yawcast::io::data::{AtomicWriter, DataError};
    /// let w = AtomicWriter::new();
    /// let _guard = w.interrupt(15);
    /// assert_eq!(w.interrupted(), Some(15));
    /// ```
    pub fn interrupt(&self, signal: i32) -> std::sync::MutexGuard<'_, ()> {
        self.signal
            .store(signal.max(1), std::sync::atomic::Ordering::SeqCst);
        self.lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// [`write_all_atomic_with`] through this writer.
    ///
    /// # Errors
    /// As [`write_all_atomic_with`]; [`DataError::Interrupted`] once [`AtomicWriter::interrupt`]
    /// has been called.
    ///
    /// ```
    /// use yawcast::io::data::{AtomicWriter, DataError};
    /// let w = AtomicWriter::new();
    /// let p = std::env::temp_dir().join(format!("yawcast-doc-w-{}.txt", std::process::id()));
    /// drop(w.interrupt(2));
    /// let e = w.write_all(&[(p.clone(), b"x".to_vec())], &mut |a, b| std::fs::rename(a, b));
    /// assert!(matches!(e, Err(DataError::Interrupted { signal: 2 })));
    /// assert!(!p.exists());
    /// ```
    pub fn write_all(
        &self,
        files: &[(PathBuf, Vec<u8>)],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
    ) -> Result<(), DataError> {
        let refs: Vec<(&Path, &[u8])> = files
            .iter()
            .map(|(p, b)| (p.as_path(), b.as_slice()))
            .collect();
        self.write_all_refs(&refs, rename)
    }

    fn write_all_refs(
        &self,
        files: &[(&Path, &[u8])],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
    ) -> Result<(), DataError> {
        let _held = self
            .lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let mut tx = Transaction::default();
        let res = self.transact(files, rename, &mut tx);
        match res {
            Ok(()) => {
                tx.commit();
                Ok(())
            }
            Err(e) => {
                let unrestored = tx.roll_back();
                let e = match self.interrupted() {
                    Some(signal) => DataError::Interrupted { signal },
                    None => e,
                };
                match (e, unrestored) {
                    (e, None) => Err(e),
                    (DataError::Io { path, source }, Some(what)) => Err(DataError::Io {
                        path,
                        source: std::io::Error::new(source.kind(), format!("{source}; {what}")),
                    }),
                    (e, Some(_)) => Err(e),
                }
            }
        }
    }

    fn transact(
        &self,
        files: &[(&Path, &[u8])],
        rename: &mut dyn FnMut(&Path, &Path) -> std::io::Result<()>,
        tx: &mut Transaction,
    ) -> Result<(), DataError> {
        let stop = || {
            self.interrupted()
                .map(|signal| DataError::Interrupted { signal })
        };
        if let Some(e) = stop() {
            return Err(e);
        }
        let io = |path: &Path, source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        for (i, (path, _)) in files.iter().enumerate() {
            if files[..i].iter().any(|(p, _)| p == path) {
                return Err(io(
                    path,
                    std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "two outputs of one command go to this file",
                    ),
                ));
            }
        }
        for (path, bytes) in files {
            if path.is_dir() {
                return Err(io(
                    path,
                    std::io::Error::other("a directory stands where the file should go"),
                ));
            }
            if let Some(d) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                let missing: Vec<PathBuf> = d
                    .ancestors()
                    .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
                    .map(Path::to_path_buf)
                    .collect();
                std::fs::create_dir_all(d).map_err(|e| io(path, e))?;
                tx.dirs.extend(missing);
            }
            let tmp = side_name(path, "tmp");
            tx.temps.push(tmp.clone());
            let written = (|| {
                let mut f = std::fs::File::create(&tmp)?;
                f.write_all(bytes)?;
                f.sync_all()
            })();
            written.map_err(|e| io(path, e))?;
            if let Some(e) = stop() {
                return Err(e);
            }
        }
        for (path, _) in files {
            if path.exists() {
                let bak = side_name(path, "bak");
                let _ = std::fs::remove_file(&bak);
                std::fs::hard_link(path, &bak)
                    .or_else(|_| std::fs::copy(path, &bak).map(|_| ()))
                    .map_err(|e| io(path, e))?;
                tx.backups.push((path.to_path_buf(), bak));
            }
        }
        for (i, (path, _)) in files.iter().enumerate() {
            if let Some(e) = stop() {
                return Err(e);
            }
            rename(&tx.temps[i], path).map_err(|e| io(path, e))?;
            tx.renamed.push(path.to_path_buf());
        }
        Ok(())
    }
}

/// `.<name>.<what><pid>` beside `path`.
fn side_name(path: &Path, what: &str) -> PathBuf {
    let fname = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{fname}.{what}{}", std::process::id()))
}

/// What one all-or-nothing write has done so far, to undo it.
#[derive(Debug, Default)]
struct Transaction {
    /// Temporary files created (removed in any case).
    temps: Vec<PathBuf>,
    /// Directories created for the outputs, deepest first within each output.
    dirs: Vec<PathBuf>,
    /// (destination, backup of its previous content).
    backups: Vec<(PathBuf, PathBuf)>,
    /// Destinations renamed into place.
    renamed: Vec<PathBuf>,
}

impl Transaction {
    fn commit(self) {
        for (_, bak) in &self.backups {
            let _ = std::fs::remove_file(bak);
        }
    }

    /// Undoes everything; names what could not be restored, if anything.
    fn roll_back(self) -> Option<String> {
        let mut failed = Vec::new();
        for dest in &self.renamed {
            if !self.backups.iter().any(|(d, _)| d == dest) {
                let _ = std::fs::remove_file(dest);
            }
        }
        for (dest, bak) in &self.backups {
            if self.renamed.contains(dest) {
                if let Err(e) = std::fs::rename(bak, dest) {
                    failed.push(format!(
                        "{} could not be restored from {}: {e}",
                        dest.display(),
                        bak.display()
                    ));
                }
            } else {
                let _ = std::fs::remove_file(bak);
            }
        }
        for t in &self.temps {
            let _ = std::fs::remove_file(t);
        }
        for d in &self.dirs {
            let _ = std::fs::remove_dir(d);
        }
        (!failed.is_empty()).then(|| failed.join("; "))
    }
}

/// Checks, before any work, that every output can be written: no two outputs share a
/// destination, no directory stands where a file should go, and the nearest existing
/// directory above each destination is a directory in which a file can be created (probed
/// with a file created and removed at once).
///
/// # Errors
/// [`DataError::Io`] naming the first output that cannot be written and why.
///
/// ```
/// use yawcast::io::data::check_outputs;
/// let dir = std::env::temp_dir().join(format!("yawcast-doc-chk-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("file"), b"").unwrap();
/// let ok = dir.join("new/sub/out.json");
/// assert!(check_outputs(&[ok.as_path()]).is_ok());
/// assert!(!dir.join("new").exists()); // nothing created
/// let blocked = dir.join("file/out.json");
/// let e = check_outputs(&[ok.as_path(), blocked.as_path()]).unwrap_err();
/// assert!(e.to_string().contains("is a file, not a directory"), "{e}");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn check_outputs(paths: &[&Path]) -> Result<(), DataError> {
    for (i, path) in paths.iter().enumerate() {
        let io = |kind: std::io::ErrorKind, msg: String| DataError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(kind, msg),
        };
        if paths[..i].contains(path) {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                "two outputs of one command go to this file".into(),
            ));
        }
        if path.is_dir() {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                "a directory stands where the file should go".into(),
            ));
        }
        let parent = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let Some(existing) = parent.ancestors().find(|a| {
            let a = if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            };
            std::fs::symlink_metadata(a).is_ok()
        }) else {
            continue;
        };
        let existing = if existing.as_os_str().is_empty() {
            Path::new(".")
        } else {
            existing
        };
        if !existing.is_dir() {
            return Err(io(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{} is a file, not a directory: the output cannot go under it",
                    existing.display()
                ),
            ));
        }
        let probe = existing.join(format!(".yawcast-probe{}", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&probe)
        {
            Ok(_) => {
                let _ = std::fs::remove_file(&probe);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => {
                return Err(io(
                    e.kind(),
                    format!("no file can be created in {}: {e}", existing.display()),
                ))
            }
        }
    }
    Ok(())
}
