//! What can be wrong with a scene: one line each, naming the scene (its file or built-in name)
//! and, for a bad value, its key.

/// What can be wrong with a scene (one line each, naming the scene and the problem).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    // The reason is in the message, not a `#[source]`, so a report of the whole chain (anyhow's
    // `{:#}`) does not say it twice.
    #[error("{path}: cannot read the scene file: {}", read_reason(.error))]
    Read {
        /// The file.
        path: String,
        /// Why.
        error: std::io::Error,
    },
    /// The file is not valid TOML or does not follow the schema.
    #[error("{path}: malformed scene file: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The parser's complaint, with line and column.
        message: String,
    },
    /// The scene parses but a value is unusable.
    #[error("{path}: {message}")]
    Invalid {
        /// The file or built-in scene name.
        path: String,
        /// What is wrong, naming the field.
        message: String,
    },
    /// No built-in scene has that name.
    #[error(
        "unknown scene '{name}' (not a built-in scene and not a .toml file; `rtoracle scenes` lists the built-ins)"
    )]
    Unknown {
        /// The name asked for.
        name: String,
    },
}

/// Why a file could not be read, in a few words ("no such file" rather than "No such file or
/// directory (os error 2)").
pub(crate) fn read_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::IsADirectory => "it is a folder".to_string(),
        std::io::ErrorKind::InvalidData => "it is not UTF-8 text".to_string(),
        _ => e.to_string(),
    }
}

/// A [`SceneError::Invalid`] of scene `path`.
pub(crate) fn invalid(path: &str, message: String) -> SceneError {
    SceneError::Invalid {
        path: path.to_string(),
        message,
    }
}
