//! Atomic file writes, and the one rule for partial work: a temporary file beside the target,
//! synced, then renamed over it; the temporaries of writes in progress are known, so a second
//! interrupting signal removes them ([`super::signals`]); and the temporaries a killed process
//! left behind are swept by a later write into the same folder.
//!
//! A temporary file is named `.NAME.tmp.HOST.BOOT.PID.N`: the host name (characters other than
//! ASCII letters, digits and `-` as `_`), the first 8 hex digits of the boot id, the process id
//! and a counter. Folders may be shared by hosts (a farm's volume), so a sweep removes only
//! this host's files whose process is gone (another boot, or no such pid now), and anyone's
//! files older than [`STALE_AFTER`].

use std::collections::HashSet;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

use super::FilmError;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Temporary files of writes in progress, removed by a second interrupting signal.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Folders already swept by this process.
static SWEPT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

/// Temporary files older than this are swept whatever host wrote them.
pub const STALE_AFTER: Duration = Duration::from_secs(24 * 3600);

/// This process's identity in temporary names: host, boot id, pid.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Owner {
    host: String,
    boot: String,
    pid: u32,
}

fn this_owner() -> &'static Owner {
    static OWNER: OnceLock<Owner> = OnceLock::new();
    OWNER.get_or_init(|| {
        let read = |p: &str| fs::read_to_string(p).ok().map(|s| s.trim().to_owned());
        let host = read("/proc/sys/kernel/hostname")
            .or_else(|| std::env::var("HOSTNAME").ok())
            .filter(|h| !h.is_empty())
            .unwrap_or_else(|| "host".to_owned());
        let boot: String = read("/proc/sys/kernel/random/boot_id")
            .unwrap_or_default()
            .chars()
            .filter(char::is_ascii_hexdigit)
            .take(8)
            .collect();
        Owner {
            host: host
                .chars()
                .take(64)
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect(),
            boot: if boot.is_empty() {
                "0".to_owned()
            } else {
                boot
            },
            pid: std::process::id(),
        }
    })
}

/// The temporary name for a write of `file_name` by `owner`.
fn temp_name(file_name: &str, owner: &Owner, n: u64) -> String {
    format!(
        ".{file_name}.tmp.{}.{}.{}.{n}",
        owner.host, owner.boot, owner.pid
    )
}

/// The owner of a temporary file named by [`temp_name`], if `name` is one.
fn parse_temp_name(name: &str) -> Option<Owner> {
    let rest = name.strip_prefix('.')?;
    let mut parts = rest.rsplitn(5, '.');
    let n = parts.next()?;
    let pid = parts.next()?;
    let boot = parts.next()?;
    let host = parts.next()?;
    let head = parts.next()?;
    if !head.ends_with(".tmp") || head.len() <= ".tmp".len() {
        return None;
    }
    n.parse::<u64>().ok()?;
    Some(Owner {
        host: host.to_owned(),
        boot: boot.to_owned(),
        pid: pid.parse().ok()?,
    })
}

/// Whether process `pid` of this boot still runs (`true` where that cannot be told).
fn alive(pid: u32) -> bool {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return true;
    }
    proc.join(pid.to_string()).exists()
}

/// Removes the temporary files in `dir` that no running process will finish: this host's of
/// processes that are gone, and any older than [`STALE_AFTER`]. Once per folder per process.
pub fn sweep(dir: &Path) {
    {
        let mut swept = SWEPT.lock().unwrap_or_else(|e| e.into_inner());
        let key = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
        if !swept.get_or_insert_with(HashSet::new).insert(key) {
            return;
        }
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let me = this_owner();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(owner) = name.to_str().and_then(parse_temp_name) else {
            continue;
        };
        let old = e
            .metadata()
            .ok()
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > STALE_AFTER);
        let dead = owner.host == me.host
            && owner.pid != me.pid
            && (owner.boot != me.boot || !alive(owner.pid));
        if old || dead {
            // Best effort: another sweeper may have been first.
            let _ = fs::remove_file(e.path());
        }
    }
}

/// Removes the temporary files of writes in progress: what a process that must exit at once
/// leaves otherwise.
pub(super) fn remove_in_flight() {
    let list = IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner());
    for p in list.iter() {
        let _ = fs::remove_file(p);
    }
}

fn track(p: &Path) {
    IN_FLIGHT
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(p.to_path_buf());
}

fn untrack(p: &Path) {
    IN_FLIGHT
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|q| q != p);
}

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
    sweep(dir);

    // Same directory as the target so the rename stays on one filesystem
    // (and is therefore atomic); hidden so it does not look like output.
    // `create_new` never clobbers a file we did not create.
    let file_name = file_name.to_string_lossy();
    let (tmp_path, file) = loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let candidate = dir.join(temp_name(&file_name, this_owner(), n));
        // Tracked before it exists, so a signal between creation and tracking cannot miss it.
        track(&candidate);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&candidate)
        {
            Ok(f) => break (candidate, f),
            Err(e) => {
                untrack(&candidate);
                if e.kind() != io::ErrorKind::AlreadyExists {
                    return Err(write_err(e));
                }
            }
        }
    };

    let result = finish_temp(file, bytes, &tmp_path, path);
    if let Err(error) = result {
        // Best effort: the original error is what matters to the caller.
        let _ = fs::remove_file(&tmp_path);
        untrack(&tmp_path);
        return Err(write_err(error));
    }
    untrack(&tmp_path);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_parse_back_to_their_owner() {
        let o = Owner {
            host: "node-07_farm_local".into(),
            boot: "1a2b3c4d".into(),
            pid: 4242,
        };
        for file in ["frame_0001.png", "a.b.c.exr", "x", "tmp.tmp.exr"] {
            let name = temp_name(file, &o, 17);
            assert_eq!(parse_temp_name(&name), Some(o.clone()), "{name}");
        }
        for not_temp in [
            "frame_0001.png",
            ".frame.png.tmp-12-0",
            ".tmp.h.b.1.2",
            ".f.png.tmp.h.b.pid.2",
            ".f.png.tmp.h.b.1.n",
        ] {
            assert_eq!(parse_temp_name(not_temp), None, "{not_temp}");
        }
    }

    #[test]
    fn a_sweep_removes_dead_and_stale_temporaries_only() {
        let d = tempfile::tempdir().unwrap();
        let me = this_owner().clone();
        // A pid above the kernel's maximum (2²²) never runs.
        let dead = Owner {
            pid: 1 << 23,
            ..me.clone()
        };
        let other_boot = Owner {
            boot: "ffffffff".into(),
            pid: 1,
            ..me.clone()
        };
        let other_host = Owner {
            host: format!("{}-other", me.host),
            pid: 1 << 23,
            ..me.clone()
        };
        let live = Owner {
            pid: 1,
            ..me.clone()
        };
        let names = [
            (temp_name("a.png", &dead, 0), false),
            (temp_name("b.png", &other_boot, 0), false),
            (temp_name("c.png", &other_host, 0), true),
            (temp_name("d.png", &me, 0), true),
            ("e.png".to_owned(), true),
        ];
        let live_kept = alive(1);
        for (n, _) in &names {
            fs::write(d.path().join(n), b"x").unwrap();
        }
        // Another host's file, a day and an hour old: stale, whoever wrote it.
        let stale = temp_name("g.png", &other_host, 1);
        let f = File::create(d.path().join(&stale)).unwrap();
        let then = std::time::SystemTime::now() - STALE_AFTER - Duration::from_secs(3600);
        f.set_modified(then).unwrap();
        drop(f);
        fs::write(d.path().join(temp_name("f.png", &live, 0)), b"x").unwrap();
        sweep(d.path());
        for (n, kept) in &names {
            assert_eq!(d.path().join(n).exists(), *kept, "{n}");
        }
        assert!(!d.path().join(&stale).exists(), "{stale}");
        assert_eq!(
            d.path().join(temp_name("f.png", &live, 0)).exists(),
            live_kept
        );
    }
}
