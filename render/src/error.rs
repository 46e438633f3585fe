//! Typed errors of the renderer: every variant names the file, key or setting and what was expected.

use std::path::PathBuf;
use thiserror::Error;

/// Anything that stops a scene from loading or an image from being written.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The scene file is not valid TOML or does not match the schema (unknown key, wrong type).
    #[error("scene {file}: {message}")]
    SceneSyntax {
        /// Scene file (or `builtin:NAME`).
        file: String,
        /// The parser's message, which names the key and line.
        message: String,
    },
    /// A key of the scene file has a value outside what is expected.
    #[error("scene {file}: key `{key}`: {message}")]
    SceneValue {
        /// Scene file (or `builtin:NAME`).
        file: String,
        /// Dotted key path, e.g. `meshes[1].translate_mm`.
        key: String,
        /// What was wrong and what is expected.
        message: String,
    },
    /// A file the scene refers to (mesh, texture, environment map) cannot be read.
    #[error("{what} file {path} cannot be read: {source}")]
    MissingFile {
        /// What the file is for ("mesh", "texture", "environment map", "scene").
        what: &'static str,
        /// The path as resolved.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// An input file refused before reading: wrong extension, not a regular file, or over its cap.
    #[error("{what} file {path}: {message}")]
    Input {
        /// What the file is for ("mesh", "texture", "environment map", "scene", "spectrum").
        what: &'static str,
        /// The path as given.
        path: PathBuf,
        /// Why it was refused, with the limit.
        message: String,
    },
    /// A mesh file could be read but not decoded.
    #[error("mesh {path}: {message}")]
    Mesh {
        /// The mesh path.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// An image file (texture, environment map) could be read but not decoded.
    #[error("image {path}: {message}")]
    Image {
        /// The image path.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A chromophore map of a skin material (scene keys `maps`, `melanin_map`, `edit_mask`, …)
    /// that cannot be read or whose texels are unusable: missing, wrong size, NaN or out of range.
    #[error("scene key `{key}`: map {path}: {message}")]
    ChromophoreMap {
        /// Dotted scene key, e.g. `materials.skin.melanin_map`.
        key: String,
        /// The map file as given.
        path: PathBuf,
        /// What is wrong, with the valid range where one applies.
        message: String,
    },
    /// A scene setting outside its valid range (the camera's).
    #[error("{name} = {value} outside {range}")]
    Setting {
        /// The scene key (e.g. `camera.fov_deg`).
        name: &'static str,
        /// The offending value.
        value: String,
        /// The valid range.
        range: &'static str,
    },
    /// An output could not be written whole (see [`skin_io::atomic`]).
    #[error(transparent)]
    Write(#[from] skin_io::atomic::AtomicWriteError),
    /// A render option outside its range (see [`crate::renderer::RenderOptions::validate`]).
    #[error(transparent)]
    Settings(#[from] SettingError),
    /// The render's worker threads could not be started.
    #[error("cannot start {threads:?} render threads: {message}")]
    Threads {
        /// The requested count (None = all cores).
        threads: Option<usize>,
        /// The thread pool's message.
        message: String,
    },
    /// An I/O error without more context (wrapped with the path where it is known).
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Writing an output image failed.
    #[error("cannot write {path}: {message}")]
    Output {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// A render option outside its valid range; `name` is the `renderer::RenderOptions` field.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("render setting {name} = {value} outside {range}")]
pub struct SettingError {
    /// The field of `renderer::RenderOptions` (e.g. `spp`, `path.max_depth`).
    pub name: &'static str,
    /// The offending value.
    pub value: String,
    /// The valid range.
    pub range: &'static str,
}

impl From<skin_io::input::InputError> for RenderError {
    fn from(e: skin_io::input::InputError) -> Self {
        use skin_io::input::InputError;
        match e {
            InputError::Unreadable { what, path, source } => {
                Self::MissingFile { what, path, source }
            }
            InputError::Refused {
                what,
                path,
                message,
            } => Self::Input {
                what,
                path,
                message,
            },
        }
    }
}

impl RenderError {
    /// Shorthand for [`RenderError::SceneValue`].
    pub fn value(file: &str, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self::SceneValue {
            file: file.to_string(),
            key: key.into(),
            message: message.into(),
        }
    }
}
