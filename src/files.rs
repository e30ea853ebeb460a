//! Reading input files: regular files only, and never more than a stated size. A FIFO would
//! block the reader forever, a device such as `/dev/zero` never ends, and a directory is a
//! mistake; each is refused by name before it is opened.

use std::io::{self, Read};
use std::path::Path;

/// The largest scene file read (RON text): 64 MiB.
pub const MAX_SCENE_BYTES: u64 = 64 << 20;
/// The largest mesh file read: 4 GiB.
pub const MAX_MESH_BYTES: u64 = 4 << 30;
/// The largest image file read (textures, and the images `compare` and `merge` read): 2 GiB.
pub const MAX_IMAGE_BYTES: u64 = 2 << 30;

fn refused(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// The metadata of `path` (symbolic links followed) if it is a regular file; a directory, FIFO,
/// socket or device is refused by name.
fn regular_file(path: &Path) -> io::Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(refused("it is a directory".into()));
    }
    if !meta.is_file() {
        return Err(refused(
            "it is not a regular file (a FIFO, socket or device)".into(),
        ));
    }
    Ok(meta)
}

/// The bytes of the regular file at `path` (symbolic links followed), if it has at most `max`.
pub fn read_bounded(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let meta = regular_file(path)?;
    let too_big = |n: u64| refused(format!("it has {n} bytes, more than the {max} allowed"));
    if meta.len() > max {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The file may grow between the size check and the read: never past the cap.
    std::fs::File::open(path)?
        .take(max + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// At most the first `max` bytes of the regular file at `path` (symbolic links followed): what
/// a header reader needs.
pub fn read_prefix(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let meta = regular_file(path)?;
    let mut bytes = Vec::with_capacity(meta.len().min(max) as usize);
    std::fs::File::open(path)?
        .take(max)
        .read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text.
pub fn read_text_bounded(path: &Path, max: u64) -> io::Result<String> {
    String::from_utf8(read_bounded(path, max)?).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_cap_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        std::fs::write(&f, "hello").unwrap();
        assert_eq!(read_bounded(&f, 5).unwrap(), b"hello");
        assert_eq!(read_text_bounded(&f, 100).unwrap(), "hello");
        let e = read_bounded(&f, 4).unwrap_err().to_string();
        assert_eq!(e, "it has 5 bytes, more than the 4 allowed");
        let e = read_bounded(dir.path(), 100).unwrap_err().to_string();
        assert_eq!(e, "it is a directory");
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(read_text_bounded(&f, 100).is_err());
        #[cfg(unix)]
        {
            // A device is refused before it is opened (reading /dev/zero would never end).
            let e = read_bounded(Path::new("/dev/zero"), 100).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
    }
}
