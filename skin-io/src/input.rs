//! The one way input files are read: the extension is checked first, then that the path is a
//! regular file (not a device, FIFO or folder) no larger than its kind's cap, and only then are
//! the bytes read (never more than the cap, even if the file grows meanwhile).
//!
//! Each kind's constants are one row of the table of what may be read (what, extensions, size
//! cap), named so the loaders and the errors cite them.

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why an input file was not read.
#[derive(Debug, Error)]
pub enum InputError {
    /// The file cannot be opened or read.
    #[error("{what} file {path} cannot be read: {source}")]
    Unreadable {
        /// What the file is for ("mesh", "texture", ...).
        what: &'static str,
        /// The path as given.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// Refused before reading: wrong extension, not a regular file, or over its cap.
    #[error("{what} file {path}: {message}")]
    Refused {
        /// What the file is for.
        what: &'static str,
        /// The path as given.
        path: PathBuf,
        /// Why it was refused, with the limit.
        message: String,
    },
}

/// A kind of input file: what it is called in errors, its extensions and its size cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputKind {
    /// What the file is for, as errors name it ("mesh", "texture", ...).
    pub what: &'static str,
    /// Accepted extensions, lower case, without the dot.
    pub extensions: &'static [&'static str],
    /// Largest accepted file, bytes.
    pub max_bytes: u64,
}

const MIB: u64 = 1 << 20;

/// A scene description (TOML), at most 4 MiB.
pub const SCENE: InputKind = InputKind {
    what: "scene",
    extensions: &["toml"],
    max_bytes: 4 * MIB,
};
/// A triangle mesh (glTF binary or Wavefront OBJ), at most 256 MiB.
pub const MESH: InputKind = InputKind {
    what: "mesh",
    extensions: &["glb", "obj"],
    max_bytes: 256 * MIB,
};
/// An sRGB albedo texture (JPEG or PNG), at most 64 MiB.
pub const TEXTURE: InputKind = InputKind {
    what: "texture",
    extensions: &["jpg", "jpeg", "png"],
    max_bytes: 64 * MIB,
};
/// An albedo texture or mask for `skin maps`: sRGB JPEG or PNG (8 or 16 bit) or linear OpenEXR,
/// at most 256 MiB.
pub const ALBEDO: InputKind = InputKind {
    what: "albedo texture",
    extensions: &["jpg", "jpeg", "png", "exr"],
    max_bytes: 256 * MIB,
};
/// A skin chromophore map (`maps.exr` of `skin maps`, or one parameter per file): OpenEXR or a grey
/// 8- or 16-bit PNG holding the values directly, at most 256 MiB.
pub const CHROMOPHORE_MAP: InputKind = InputKind {
    what: "chromophore map",
    extensions: &["exr", "png"],
    max_bytes: 256 * MIB,
};
/// A lat-long OpenEXR environment map, at most 256 MiB.
pub const ENVIRONMENT: InputKind = InputKind {
    what: "environment map",
    extensions: &["exr"],
    max_bytes: 256 * MIB,
};
/// A measured reflectance spectrum (CSV), at most 4 MiB.
pub const SPECTRUM: InputKind = InputKind {
    what: "spectrum",
    extensions: &["csv"],
    max_bytes: 4 * MIB,
};

impl InputKind {
    fn refuse(&self, path: &Path, message: String) -> InputError {
        InputError::Refused {
            what: self.what,
            path: path.to_path_buf(),
            message,
        }
    }

    fn check_extension(&self, path: &Path) -> Result<(), InputError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if ext.is_some_and(|e| self.extensions.contains(&e.as_str())) {
            return Ok(());
        }
        let list: Vec<String> = self.extensions.iter().map(|e| format!(".{e}")).collect();
        Err(self.refuse(path, format!("expected a {} file", list.join(" or "))))
    }

    fn check_metadata(&self, path: &Path, meta: &fs::Metadata) -> Result<(), InputError> {
        if !meta.is_file() {
            return Err(self.refuse(path, "not a regular file".into()));
        }
        if meta.len() > self.max_bytes {
            return Err(self.refuse(
                path,
                format!(
                    "{} bytes, more than the {} MiB a {} file may have",
                    meta.len(),
                    self.max_bytes / MIB,
                    self.what
                ),
            ));
        }
        Ok(())
    }

    /// Read the whole file after the checks of the module doc.
    pub fn read(&self, path: &Path) -> Result<Vec<u8>, InputError> {
        self.check_extension(path)?;
        let missing = |source| InputError::Unreadable {
            what: self.what,
            path: path.to_path_buf(),
            source,
        };
        // Checked before opening: opening a FIFO would block until someone writes to it.
        self.check_metadata(path, &fs::metadata(path).map_err(missing)?)?;
        let file = fs::File::open(path).map_err(missing)?;
        self.check_metadata(path, &file.metadata().map_err(missing)?)?;
        let mut bytes = Vec::new();
        file.take(self.max_bytes + 1)
            .read_to_end(&mut bytes)
            .map_err(missing)?;
        if bytes.len() as u64 > self.max_bytes {
            return Err(self.refuse(
                path,
                format!(
                    "grew past the {} MiB cap while being read",
                    self.max_bytes / MIB
                ),
            ));
        }
        Ok(bytes)
    }

    /// [`InputKind::read`] as UTF-8 text.
    pub fn read_text(&self, path: &Path) -> Result<String, InputError> {
        String::from_utf8(self.read(path)?)
            .map_err(|e| self.refuse(path, format!("not UTF-8 text ({e})")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(r: Result<Vec<u8>, InputError>) -> String {
        r.unwrap_err().to_string()
    }

    #[test]
    fn dev_zero_is_refused_as_every_kind_of_input() {
        for kind in [
            SCENE,
            MESH,
            TEXTURE,
            ALBEDO,
            CHROMOPHORE_MAP,
            ENVIRONMENT,
            SPECTRUM,
        ] {
            // The extension is checked before anything is opened.
            let e = message(kind.read(Path::new("/dev/zero")));
            assert!(e.contains("expected a ."), "{e}");
            // Under an accepted name, a device is still not a regular file.
            let dir = std::env::temp_dir().join(format!("skin-input-{}", std::process::id()));
            fs::create_dir_all(&dir).unwrap();
            let link = dir.join(format!("zero.{}", kind.extensions[0]));
            let _ = fs::remove_file(&link);
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            let e = message(kind.read(&link));
            assert!(e.contains("not a regular file"), "{e}");
            fs::remove_dir_all(&dir).unwrap();
        }
    }

    #[test]
    fn a_folder_or_an_oversized_file_is_refused_before_reading() {
        let dir = std::env::temp_dir().join(format!("skin-input-big-{}", std::process::id()));
        fs::create_dir_all(dir.join("d.csv")).unwrap();
        assert!(message(SPECTRUM.read(&dir.join("d.csv"))).contains("not a regular file"));
        // A sparse file: its size is over the cap, nothing is allocated to refuse it.
        let big = dir.join("big.csv");
        fs::File::create(&big)
            .unwrap()
            .set_len(SPECTRUM.max_bytes + 1)
            .unwrap();
        let e = message(SPECTRUM.read(&big));
        assert!(e.contains("4 MiB"), "{e}");
        fs::write(dir.join("ok.csv"), b"lambda_nm,reflectance\n").unwrap();
        assert_eq!(
            SPECTRUM.read_text(&dir.join("ok.csv")).unwrap(),
            "lambda_nm,reflectance\n"
        );
        fs::remove_dir_all(&dir).unwrap();
    }
}
