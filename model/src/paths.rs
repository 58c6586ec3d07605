//! Where mesh files named in a URDF are found: `package://` URLs through a
//! search path, `file://` URLs and absolute paths as they are, relative paths
//! against the URDF file's folder.

use std::path::{Path, PathBuf};

/// The environment variable holding extra package folders, separated like
/// `PATH` (`:` on Unix). ROS's `ROS_PACKAGE_PATH` is read as well, after it.
pub const PACKAGE_PATH_ENV: &str = "GJKD_PACKAGE_PATH";

/// A search path for `package://NAME/REST` URLs: in each folder `DIR`, the
/// file is `DIR/NAME/REST`, or `DIR/REST` when `DIR` itself is named `NAME`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PackagePath {
    /// The folders, searched in order.
    pub dirs: Vec<PathBuf>,
}

impl PackagePath {
    /// A search path of these folders only.
    pub fn new(dirs: impl IntoIterator<Item = PathBuf>) -> Self {
        PackagePath {
            dirs: dirs.into_iter().collect(),
        }
    }

    /// `dirs`, then the folders of [`PACKAGE_PATH_ENV`], then those of
    /// `ROS_PACKAGE_PATH`.
    pub fn with_env(dirs: impl IntoIterator<Item = PathBuf>) -> Self {
        let mut path = Self::new(dirs);
        for var in [PACKAGE_PATH_ENV, "ROS_PACKAGE_PATH"] {
            if let Some(value) = std::env::var_os(var) {
                path.dirs
                    .extend(std::env::split_paths(&value).filter(|d| !d.as_os_str().is_empty()));
            }
        }
        path
    }

    /// The file a URDF's `filename` names, `base` being the URDF file's
    /// folder (`None` for URDF text, whose relative paths are then relative
    /// to the working folder).
    ///
    /// # Errors
    /// The `package://` URL found in no folder: the message lists where it
    /// was looked for. Other paths are returned as they are, whether or not
    /// they exist (reading them says).
    pub fn resolve(&self, filename: &str, base: Option<&Path>) -> Result<PathBuf, String> {
        if let Some(rest) = filename.strip_prefix("package://") {
            let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
            let mut tried = Vec::new();
            for dir in &self.dirs {
                let mut candidates = vec![dir.join(package).join(inner)];
                if dir.file_name().is_some_and(|n| n == package) {
                    candidates.push(dir.join(inner));
                }
                for c in candidates {
                    if c.is_file() {
                        return Ok(c);
                    }
                    tried.push(c.display().to_string());
                }
            }
            return Err(if tried.is_empty() {
                format!(
                    "{filename}: no package folders to search (give them with \
                     --package-path or {PACKAGE_PATH_ENV})"
                )
            } else {
                format!("{filename}: not found (tried {})", tried.join(", "))
            });
        }
        let plain = filename.strip_prefix("file://").unwrap_or(filename);
        let path = Path::new(plain);
        Ok(match base {
            Some(base) if path.is_relative() => base.join(path),
            _ => path.to_path_buf(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn package_urls_relative_and_absolute_paths_resolve() {
        let root = std::env::temp_dir().join(format!("gjkd-model-paths-{}", std::process::id()));
        let mesh = root.join("arm_description/meshes/link.stl");
        std::fs::create_dir_all(mesh.parent().unwrap()).unwrap();
        std::fs::write(&mesh, b"solid x\nendsolid x\n").unwrap();
        let path = PackagePath::new([root.clone()]);
        assert_eq!(
            path.resolve("package://arm_description/meshes/link.stl", None),
            Ok(mesh.clone())
        );
        // A folder named like the package is the package itself.
        let inside = PackagePath::new([root.join("arm_description")]);
        assert_eq!(
            inside.resolve("package://arm_description/meshes/link.stl", None),
            Ok(mesh.clone())
        );
        let missing = path.resolve("package://other/x.stl", None).unwrap_err();
        assert!(missing.contains("not found"), "{missing}");
        let none = PackagePath::default().resolve("package://p/x.stl", None);
        assert!(none.unwrap_err().contains(PACKAGE_PATH_ENV));
        assert_eq!(
            path.resolve("meshes/a.stl", Some(Path::new("/robots/arm"))),
            Ok(PathBuf::from("/robots/arm/meshes/a.stl"))
        );
        assert_eq!(
            path.resolve("file:///abs/a.stl", Some(Path::new("/robots"))),
            Ok(PathBuf::from("/abs/a.stl"))
        );
        std::fs::remove_dir_all(&root).unwrap();
    }
}
