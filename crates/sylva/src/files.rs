//! Reading the files people give and writing the files Sylva makes: input read with a hard
//! size cap and a UTF-8 check; every output written to a temporary name and renamed, so no
//! half-written file is ever left behind; and [`Outputs`], the files of one command, which
//! appear together or not at all.

use std::io::Write;
use std::path::{Path, PathBuf};

use sylva_gltf::export::{Format, Glb, GlbOptions};

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
    let cannot = |e: std::io::Error| InputError {
        io: Some(e.kind()),
        ..InputError::file(path, format!("cannot read: {e}"))
    };
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

/// Refuses an output folder that cannot be made because it, or a folder it would go in, is
/// a file: a long run checks before it begins, so that none of its work is lost at the end.
pub fn check_out_dir(path: &Path) -> Result<(), InputError> {
    let existing = path
        .ancestors()
        .find(|d| !d.as_os_str().is_empty() && d.exists());
    match existing {
        Some(d) if !d.is_dir() => Err(InputError::file(
            d,
            "is a file, not a folder: the outputs go in a folder",
        )),
        _ => Ok(()),
    }
}

/// Makes a folder and its parents.
pub fn create_dir(path: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(path).map_err(|source| Error::Io {
        action: "creating",
        path: path.to_owned(),
        source,
    })
}

/// Removes the temporary files that a killed command left in `dir` while writing one of
/// `names` (`.<name>.<anything>.tmp`); nothing else is touched.
pub fn remove_leftovers(dir: &Path, names: &[&str]) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(file) = file.to_str() else { continue };
        let ours = file.ends_with(".tmp")
            && file.starts_with('.')
            && names
                .iter()
                .any(|n| file.trim_start_matches('.').starts_with(&format!("{n}.")));
        if ours {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The files one command writes, which appear together or not at all. Each file is written
/// to a temporary name beside its destination as it is added; [`Outputs::commit`] renames
/// them all into place. Dropped without a commit (an error on the way), the temporary
/// files go, and so do the folders it made.
#[derive(Debug, Default)]
pub struct Outputs {
    /// `(temporary, destination)`, in the order added.
    staged: Vec<(PathBuf, PathBuf)>,
    /// Folders made for the outputs, outermost first.
    made: Vec<PathBuf>,
}

impl Outputs {
    /// No files yet.
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// Makes `dir` (and its missing parents) for the outputs; they are removed again if the
    /// outputs are dropped, when empty.
    pub fn create_dir(&mut self, dir: &Path) -> Result<(), Error> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        create_dir(dir)?;
        self.made.extend(missing.into_iter().rev());
        Ok(())
    }

    /// Adds a file: written now under a temporary name, renamed on commit.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<(), Error> {
        self.add_with(path, |file| file.write_all(bytes))
    }

    /// Adds a file whose bytes `write` streams into it (so they need not be in memory at
    /// once): written now under a temporary name, renamed on commit.
    pub fn add_with(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> Result<(), Error> {
        let name = path
            .file_name()
            .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
        let temp = path.with_file_name(format!(
            ".{name}.{}-{}.tmp",
            std::process::id(),
            self.staged.len()
        ));
        // Written whole and synced before the commit renames it; the destination is named in
        // errors (the temporary name is ours, not the user's).
        let written = (|| {
            let mut file = std::fs::File::create(&temp)?;
            write(&mut file)?;
            file.sync_all()
        })();
        self.staged.push((temp, path.to_owned()));
        written.map_err(|source| Error::Io {
            action: "writing",
            path: path.to_owned(),
            source,
        })?;
        Ok(())
    }

    /// Adds every file of a scene's export to `path` (an OBJ's MTL and textures too); a GLB
    /// is streamed into its file.
    pub fn add_scene(&mut self, path: &Path, scene: &sylva_mesh::Scene<'_>) -> Result<(), Error> {
        self.add_scene_with(path, scene, &GlbOptions::default())
    }

    /// As [`Outputs::add_scene`], a GLB laid out as `options` say (instancing,
    /// quantisation); other formats ignore them.
    pub fn add_scene_with(
        &mut self,
        path: &Path,
        scene: &sylva_mesh::Scene<'_>,
        options: &GlbOptions,
    ) -> Result<(), Error> {
        if Format::from_path(path)? == Format::Glb {
            return self.add_glb(path, &mut Glb::of_scene(scene, *options)?);
        }
        for (file, bytes) in sylva_gltf::export::scene_files(path, scene)? {
            self.add(&file, &bytes)?;
        }
        Ok(())
    }

    /// Adds a GLB laid out beforehand, streamed into its file.
    pub fn add_glb(&mut self, path: &Path, glb: &mut Glb<'_>) -> Result<(), Error> {
        self.add_with(path, |file| glb.write_to(file))
    }

    /// Renames every file into place, in the order added. A file that cannot be renamed
    /// (its destination is a folder, say) leaves no temporary file behind, nor do the ones
    /// after it.
    pub fn commit(mut self) -> Result<(), Error> {
        while let Some((temp, path)) = self.staged.first() {
            // On an error, this file and the rest stay staged, and the drop removes them.
            std::fs::rename(temp, path).map_err(|source| Error::Io {
                action: "writing",
                path: path.clone(),
                source,
            })?;
            self.staged.remove(0);
        }
        self.made.clear();
        Ok(())
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        for (temp, _) in &self.staged {
            let _ = std::fs::remove_file(temp);
        }
        for dir in self.made.iter().rev() {
            // Only empty folders go: anything else in them is not ours.
            let _ = std::fs::remove_dir(dir);
        }
    }
}
