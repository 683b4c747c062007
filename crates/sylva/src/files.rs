//! Reading the files people give and writing the files Sylva makes: text read whole with a
//! size limit and a UTF-8 check, and every output written to a temporary name and renamed,
//! so no half-written file is ever left behind.

use std::path::Path;

use crate::error::{Error, InputError};

/// Largest text file read: 64 MiB.
pub const MAX_TEXT: u64 = 64 << 20;

/// Reads a UTF-8 text file, refusing files over [`MAX_TEXT`] bytes.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    let meta =
        std::fs::metadata(path).map_err(|e| InputError::file(path, format!("cannot read: {e}")))?;
    if meta.len() > MAX_TEXT {
        return Err(InputError::file(
            path,
            format!("file is {} bytes; at most {MAX_TEXT} are read", meta.len()),
        ));
    }
    let bytes =
        std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        InputError::file(
            path,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// Reads a binary file (a GLB), refusing files over `limit` bytes.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    let meta =
        std::fs::metadata(path).map_err(|e| InputError::file(path, format!("cannot read: {e}")))?;
    if meta.len() > limit {
        return Err(InputError::file(
            path,
            format!("file is {} bytes; at most {limit} are read", meta.len()),
        ));
    }
    std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read: {e}")))
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
