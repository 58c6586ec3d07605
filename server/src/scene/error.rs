//! What can be wrong with a scene file.

/// What can be wrong with a scene file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene file {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The TOML does not parse or does not match the schema.
    #[error("invalid scene: {0}")]
    Parse(#[from] toml::de::Error),
    /// A key the format does not have (a misspelt key would otherwise be
    /// ignored and its default used without a word).
    #[error("{place}: unknown key `{key}` (allowed here: {allowed})")]
    UnknownKey {
        /// Where: the object's name or index, and the piece or pose.
        place: String,
        /// The key.
        key: String,
        /// The keys allowed in that place.
        allowed: String,
    },
    /// An object is not a valid shape.
    #[error("object `{name}`: {reason}")]
    Object {
        /// The object's name.
        name: String,
        /// Why.
        reason: String,
    },
}
