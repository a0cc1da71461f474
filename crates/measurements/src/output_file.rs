//! Every file a command writes, written atomically: the bytes go to a temporary file in the
//! target's own folder, are synced to disk, and the temporary file is then renamed over the
//! target. A crash or a `kill -9` leaves either the old file or the new one, never half of one.
//!
//! A symbolic link at the target is followed (a chain of them too) and the file it points to is
//! replaced, the link left in place; anything else that is not a regular file (a directory, a
//! FIFO, a socket, a device node such as `/dev/null`) is refused rather than replaced by a
//! regular file.

use crate::ErrorKind;
pub use crate::error_kind::FileKind;
use errors::Error;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The most symbolic links followed from an output path: Linux's own limit before `ELOOP`
/// (`MAXSYMLINKS` = 40), so that a chain the operating system itself would follow is followed.
pub const MAX_SYMLINKS: usize = 40;

fn kind_of(file_type: std::fs::FileType) -> FileKind {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return FileKind::Fifo;
        }
        if file_type.is_socket() {
            return FileKind::Socket;
        }
        if file_type.is_char_device() {
            return FileKind::CharacterDevice;
        }
        if file_type.is_block_device() {
            return FileKind::BlockDevice;
        }
    }
    if file_type.is_dir() { FileKind::Directory } else { FileKind::Other }
}

/// The file an output to `path` replaces: `path` itself, or where the chain of symbolic links
/// starting at it ends. The file need not exist; if something exists there that is not a regular
/// file, it is refused ([`ErrorKind::OutputNotRegularFile`], [`ErrorKind::OutputSymlinkChain`]).
pub fn output_target(path: &Path) -> Result<PathBuf, Error> {
    let shown = || path.display().to_string();
    let mut current = path.to_path_buf();
    for _ in 0..=MAX_SYMLINKS {
        let metadata = match std::fs::symlink_metadata(&current) {
            Ok(metadata) => metadata,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(current),
            Err(source) => return Err(Error::io(current.display().to_string(), source)),
        };
        let file_type = metadata.file_type();
        if file_type.is_file() {
            return Ok(current);
        }
        if !file_type.is_symlink() {
            let path = if current == path {
                shown()
            } else {
                format!("{} (the link's target {})", shown(), current.display())
            };
            return Err(Error::in_file(path, ErrorKind::OutputNotRegularFile { kind: kind_of(file_type) }));
        }
        let link = std::fs::read_link(&current).map_err(|source| Error::io(current.display().to_string(), source))?;
        // A relative link is relative to the folder that holds the link.
        current = match current.parent() {
            Some(folder) if link.is_relative() => folder.join(link),
            _ => link,
        };
    }
    Err(Error::in_file(shown(), ErrorKind::OutputSymlinkChain { links: MAX_SYMLINKS }))
}

/// Writes `bytes` to `path` atomically (see the module doc).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let mut file = OutputFile::create(path)?;
    file.write_all(bytes).map_err(|source| Error::io(path.display().to_string(), source))?;
    file.finish()
}

/// Makes each temporary name of this process distinct.
static TEMPORARY_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// An output file being written: a buffered writer into a temporary file next to the target.
/// [`OutputFile::finish`] syncs it and renames it over the target; dropped unfinished (an error,
/// a panic), the temporary file is removed and the target left as it was.
#[derive(Debug)]
pub struct OutputFile {
    /// The path as the caller gave it, for messages.
    shown: String,
    /// The file replaced: the path, or the end of its chain of symbolic links.
    target: PathBuf,
    temporary: PathBuf,
    writer: Option<BufWriter<File>>,
}

impl OutputFile {
    /// Starts writing `path`: resolves its target ([`output_target`]) and creates the temporary
    /// file in the target's folder, with the target's permissions where it exists.
    pub fn create(path: &Path) -> Result<OutputFile, Error> {
        let shown = path.display().to_string();
        let io = |source| Error::io(shown.clone(), source);
        let target = output_target(path)?;
        let folder = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = target.file_name().map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
        let (temporary, file) = loop {
            let n = TEMPORARY_COUNTER.fetch_add(1, Ordering::Relaxed);
            let temporary = folder.join(format!(".{name}.{}-{n}.tmp", std::process::id()));
            // create_new: never truncate a file that happens to have this name.
            match OpenOptions::new().write(true).create_new(true).open(&temporary) {
                Ok(file) => break (temporary, file),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 1_000_000 => continue,
                Err(source) => return Err(io(source)),
            }
        };
        let output = OutputFile { shown: shown.clone(), target, temporary, writer: Some(BufWriter::new(file)) };
        // A replaced file keeps its mode (an executable stays executable, a private file private).
        if let Ok(existing) = std::fs::metadata(&output.target) {
            std::fs::set_permissions(&output.temporary, existing.permissions()).map_err(io)?;
        }
        Ok(output)
    }

    /// The file this output replaces when finished (the end of a symbolic link chain).
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flushes and syncs the temporary file, then renames it over the target.
    pub fn finish(mut self) -> Result<(), Error> {
        let io = |source| Error::io(self.shown.clone(), source);
        let writer = self.writer.take().expect("an OutputFile is finished once (finish takes it by value)");
        let result = (|| {
            let file = writer.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            drop(file);
            std::fs::rename(&self.temporary, &self.target)
        })();
        if let Err(source) = result {
            let _ = std::fs::remove_file(&self.temporary);
            return Err(io(source));
        }
        // The rename is durable once the folder is synced; not every file system lets a folder
        // be opened and synced, and the new file is complete either way, so this is best effort.
        if let Some(folder) = self.target.parent().filter(|p| !p.as_os_str().is_empty())
            && let Ok(folder) = File::open(folder)
        {
            let _ = folder.sync_all();
        }
        Ok(())
    }
}

impl Write for OutputFile {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.writer.as_mut().map_or(Ok(0), |w| w.write(bytes))
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer.as_mut().map_or(Ok(()), BufWriter::flush)
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if let Some(writer) = self.writer.take() {
            drop(writer);
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_file_has_the_bytes_and_no_temporary_file_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, "old content, longer than the new one\n").unwrap();
        write_file(&path, b"new\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new\n");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.csv")]);
    }

    #[test]
    fn a_dropped_writer_removes_its_temporary_file_and_leaves_the_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, "old\n").unwrap();
        {
            let mut file = OutputFile::create(&path).unwrap();
            file.write_all(&vec![b'x'; 100_000]).unwrap();
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "the temporary file exists while writing");
        }
        assert_eq!(std::fs::read(&path).unwrap(), b"old\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_streamed_file_appears_only_when_finished() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("new.csv");
        let mut file = OutputFile::create(&path).unwrap();
        writeln!(file, "a,b").unwrap();
        assert!(!path.exists());
        file.finish().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_chain_is_followed_and_the_links_stay_links() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.csv");
        std::fs::write(&real, "old\n").unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        // sub/first -> ../second (relative, from the link's own folder) -> real.csv (absolute)
        let second = dir.path().join("second");
        std::os::unix::fs::symlink(&real, &second).unwrap();
        let first = sub.join("first");
        std::os::unix::fs::symlink("../second", &first).unwrap();
        assert_eq!(output_target(&first).unwrap(), real);
        write_file(&first, b"new\n").unwrap();
        assert!(std::fs::symlink_metadata(&first).unwrap().file_type().is_symlink());
        assert!(std::fs::symlink_metadata(&second).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new\n");
    }

    #[cfg(unix)]
    #[test]
    fn a_dangling_symlink_gets_its_target_created() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink("target.csv", &link).unwrap();
        write_file(&link, b"made\n").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(dir.path().join("target.csv")).unwrap(), b"made\n");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_loop_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        assert!(matches!(
            write_file(&a, b"x").unwrap_err().kind::<ErrorKind>(),
            Some(ErrorKind::OutputSymlinkChain { links: MAX_SYMLINKS })
        ));
    }

    #[test]
    fn a_directory_is_refused_and_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("folder");
        std::fs::create_dir(&folder).unwrap();
        let error = write_file(&folder, b"x").unwrap_err();
        assert!(
            matches!(
                error.kind::<ErrorKind>(),
                Some(ErrorKind::OutputNotRegularFile { kind: FileKind::Directory, .. })
            ),
            "{error:?}"
        );
        assert!(error.to_string().contains("is a directory"), "{error}");
        assert!(folder.is_dir());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file made");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_to_a_directory_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(dir.path(), &link).unwrap();
        assert!(matches!(
            write_file(&link, b"x").unwrap_err().kind::<ErrorKind>(),
            Some(ErrorKind::OutputNotRegularFile { kind: FileKind::Directory })
        ));
    }

    #[cfg(unix)]
    #[test]
    fn a_character_device_is_refused() {
        let error = output_target(Path::new("/dev/null")).unwrap_err();
        assert!(
            matches!(
                error.kind::<ErrorKind>(),
                Some(ErrorKind::OutputNotRegularFile { kind: FileKind::CharacterDevice, .. })
            ),
            "{error:?}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn an_existing_files_permissions_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("script.sh");
        std::fs::write(&path, "old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o750)).unwrap();
        write_file(&path, b"new").unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o777, 0o750);
    }
}
