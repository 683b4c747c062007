//! Reading the files people give and writing the files Sylva makes: text read whole with a
//! size limit and a UTF-8 check, and every output written to a temporary name and renamed,
//! so no half-written file is ever left behind.

use std::path::Path;

use crate::error::{Error, InputError};

/// Largest text file read: 64 MiB.
pub const MAX_TEXT: u64 = 64 << 20;

/// Reads a UTF-8 text file of at most [`MAX_TEXT`] bytes. A leading byte-order mark is
/// dropped (editors show none, so columns stay the editor's).
pub fn read_text(path: &Path) -> Result<String, InputError> {
    let bytes = read_bytes(path, MAX_TEXT)?;
    let mut text = String::from_utf8(bytes).map_err(|e| {
        InputError::file(
            path,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Reads a file of at most `limit` bytes. The limit is a hard cap on what is read, not a
/// check of the size the file reports, so a device or a pipe (`/dev/zero`) is refused
/// after `limit` bytes too.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    use std::io::Read;
    let cannot = |e: std::io::Error| InputError::file(path, format!("cannot read: {e}"));
    let file = std::fs::File::open(path).map_err(cannot)?;
    if file.metadata().map_err(cannot)?.is_dir() {
        return Err(InputError::file(path, "is a folder, not a file"));
    }
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::file(
            path,
            format!("file is over {limit} bytes; at most {limit} are read"),
        ));
    }
    Ok(bytes)
}

/// Writes `bytes` to `path` through a temporary file and a rename.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    sylva_core::io::write_atomic(path, bytes).map_err(|source| Error::Io {
        action: "writing",
        path: path.to_owned(),
        source,
    })
}

/// Makes a folder and its parents.
pub fn create_dir(path: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(path).map_err(|source| Error::Io {
        action: "creating",
        path: path.to_owned(),
        source,
    })
}
