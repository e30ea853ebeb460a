//! Atomic file writes: a temporary file beside the target, synced, then renamed over it.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use super::FilmError;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`: a reader
/// never sees a partial file, and an interrupted write leaves no file with the final name.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FilmError> {
    let write_err = |error| FilmError::Write {
        path: path.to_path_buf(),
        error,
    };
    let Some(file_name) = path.file_name() else {
        return Err(write_err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "path has no file name",
        )));
    };
    // `Path::parent` of a bare file name is "", which means the cwd.
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    fs::create_dir_all(dir).map_err(|error| FilmError::CreateDir {
        dir: dir.to_path_buf(),
        path: path.to_path_buf(),
        error,
    })?;

    // Same directory as the target so the rename stays on one filesystem
    // (and is therefore atomic); hidden so it does not look like output.
    // `create_new` never clobbers a file we did not create.
    let (tmp_path, file) = loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let name = format!(
            ".{}.tmp-{}-{n}",
            file_name.to_string_lossy(),
            std::process::id()
        );
        let candidate = dir.join(name);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&candidate)
        {
            Ok(f) => break (candidate, f),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(write_err(e)),
        }
    };

    let result = finish_temp(file, bytes, &tmp_path, path);
    if let Err(error) = result {
        // Best effort: the original error is what matters to the caller.
        let _ = fs::remove_file(&tmp_path);
        return Err(write_err(error));
    }
    sync_dir(dir);
    Ok(())
}

fn finish_temp(mut file: File, bytes: &[u8], tmp: &Path, target: &Path) -> io::Result<()> {
    file.write_all(bytes)?;
    // Data must be on disk before the rename makes it visible, or a crash
    // could leave a complete-looking but empty target.
    file.sync_all()?;
    drop(file);
    fs::rename(tmp, target)
}

/// Persists the rename itself; failure only weakens crash durability, so it
/// is ignored.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}
