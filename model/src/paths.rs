//! Where mesh files named in a URDF are found: `package://` URLs through a
//! search path, `file://` URLs and absolute paths as they are, relative paths
//! against the URDF file's folder.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

/// The environment variable holding extra package folders, separated like
/// `PATH` (`:` on Unix). ROS's `ROS_PACKAGE_PATH` is read as well, after it,
/// then ROS 2's `AMENT_PREFIX_PATH` (each prefix's `share` folder).
pub const PACKAGE_PATH_ENV: &str = "GJKD_PACKAGE_PATH";

/// How many folder levels below a search folder a package is looked for:
/// a workspace's `src`, a repository, a folder of repositories.
const CRAWL_DEPTH: usize = 6;

/// How many folders one search folder's crawl reads at most, so that a
/// search path naming a large tree (a home folder) fails in bounded time.
const CRAWL_FOLDERS: usize = 20_000;

/// A search path for `package://NAME/REST` URLs, searched as ROS does: in
/// each folder `DIR`, the file is `DIR/NAME/REST`, or `DIR/REST` when `DIR`
/// itself is named `NAME`; failing those, `PKG/REST` for the first package
/// folder `PKG` below a search folder (one holding a `package.xml`) whose
/// manifest's `<name>`, or whose folder name, is `NAME`, or, outside
/// packages, for the first folder named `NAME` that holds `REST`.
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
    /// `ROS_PACKAGE_PATH`, then the `share` folder of each prefix in
    /// `AMENT_PREFIX_PATH` (where ROS 2 installs a package's files).
    pub fn with_env(dirs: impl IntoIterator<Item = PathBuf>) -> Self {
        let mut path = Self::new(dirs);
        let split = |var: &str| {
            std::env::var_os(var)
                .map(|value| std::env::split_paths(&value).collect::<Vec<_>>())
                .unwrap_or_default()
                .into_iter()
                .filter(|d| !d.as_os_str().is_empty())
        };
        path.dirs.extend(split(PACKAGE_PATH_ENV));
        path.dirs.extend(split("ROS_PACKAGE_PATH"));
        path.dirs
            .extend(split("AMENT_PREFIX_PATH").map(|prefix| prefix.join("share")));
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
            // Deeper, as ROS crawls its package path: only once the direct
            // places fail, which keeps the common layout free of walks.
            for dir in &self.dirs {
                if let Some(found) = find_package(dir, package, inner) {
                    let c = found.join(inner);
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
                format!(
                    "{filename}: not found (tried {}; no other package `{package}` \
                     below those folders)",
                    tried.join(", ")
                )
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

/// The package `name` below `dir`, for the file `inner` in it, breadth
/// first (the shallowest wins, then the alphabetically first): a folder
/// holding a `package.xml` whose `<name>` is `name` (when its manifest
/// gives no name, whose own name is), as ROS finds it; or, where no
/// manifests mark the packages (collections of descriptions copied without
/// them), a folder named `name` that holds `inner`. As ROS's crawl does,
/// it does not look inside a package for others, nor inside hidden folders
/// or those marked `CATKIN_IGNORE` or `COLCON_IGNORE`; it goes
/// [`CRAWL_DEPTH`] levels down and reads at most [`CRAWL_FOLDERS`] folders.
fn find_package(dir: &Path, name: &str, inner: &str) -> Option<PathBuf> {
    let mut queue = VecDeque::from([(dir.to_path_buf(), 0)]);
    let mut read = 0;
    while let Some((folder, depth)) = queue.pop_front() {
        if read == CRAWL_FOLDERS {
            return None;
        }
        read += 1;
        if depth > 0 {
            let manifest = folder.join("package.xml");
            if manifest.is_file() {
                if package_name(&manifest, &folder).as_deref() == Some(name) {
                    return Some(folder);
                }
                continue;
            }
            if ["CATKIN_IGNORE", "COLCON_IGNORE"]
                .iter()
                .any(|mark| folder.join(mark).exists())
            {
                continue;
            }
            if folder.file_name().is_some_and(|n| n == name) && folder.join(inner).is_file() {
                return Some(folder);
            }
        }
        if depth == CRAWL_DEPTH {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        let mut children: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .filter(|e| e.file_type().is_ok_and(|t| t.is_dir() || t.is_symlink()))
            .map(|e| e.path())
            .filter(|p| {
                p.is_dir()
                    && p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| !n.starts_with('.'))
            })
            .collect();
        children.sort();
        queue.extend(children.into_iter().map(|c| (c, depth + 1)));
    }
    None
}

/// A package's name: its manifest's `<name>`, or its folder's name when
/// the manifest cannot be read or names none.
fn package_name(manifest: &Path, folder: &Path) -> Option<String> {
    let from_manifest = std::fs::read_to_string(manifest).ok().and_then(|text| {
        let doc = roxmltree::Document::parse(&text).ok()?;
        let name = doc
            .root_element()
            .children()
            .find(|n| n.has_tag_name("name"))?
            .text()?
            .trim()
            .to_owned();
        (!name.is_empty()).then_some(name)
    });
    from_manifest.or_else(|| folder.file_name()?.to_str().map(str::to_owned))
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

    /// Writes `package.xml` naming `name` in `folder` (no `<name>` if
    /// `None`), and a mesh file at `folder/meshes/link.stl`.
    fn package(folder: &Path, name: Option<&str>) -> PathBuf {
        let mesh = folder.join("meshes/link.stl");
        std::fs::create_dir_all(mesh.parent().unwrap()).unwrap();
        std::fs::write(&mesh, b"solid x\nendsolid x\n").unwrap();
        let name = name.map_or(String::new(), |n| format!("<name>\n  {n}\n</name>"));
        std::fs::write(
            folder.join("package.xml"),
            format!("<?xml version=\"1.0\"?>\n<package format=\"2\">{name}<version>1.0.0</version></package>"),
        )
        .unwrap();
        mesh
    }

    #[test]
    fn packages_below_the_search_folders_are_found_as_ros_finds_them() {
        let root = std::env::temp_dir().join(format!("gjkd-model-crawl-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        // A workspace of repositories: the package's folder is named unlike
        // the package, three levels down.
        let arm = package(
            &root.join("ws/src/arm-repo/arm_ros"),
            Some("arm_description"),
        );
        // Named by its folder when its manifest names none.
        let hand = package(&root.join("ws/src/hand_description"), None);
        // Not found: inside a hidden folder, under an ignore mark, inside
        // another package, too deep.
        package(&root.join("ws/.cache/gripper"), Some("gripper"));
        package(&root.join("ws/src/ignored/wrist"), Some("wrist"));
        std::fs::write(root.join("ws/src/ignored/CATKIN_IGNORE"), b"").unwrap();
        package(
            &root.join("ws/src/arm-repo/arm_ros/nested/base"),
            Some("base"),
        );
        package(&root.join("ws/a/b/c/d/e/f/deep"), Some("deep"));
        // With no manifest, a folder of the package's name that holds the
        // file: not the first such folder, which lacks it.
        let bare = root.join("ws/src/z/copies/bare_description/meshes/link.stl");
        std::fs::create_dir_all(root.join("ws/src/a/bare_description")).unwrap();
        std::fs::create_dir_all(bare.parent().unwrap()).unwrap();
        std::fs::write(&bare, b"solid x\nendsolid x\n").unwrap();
        // The shallower of two packages of one name wins.
        let near = package(&root.join("ws/src/tool"), Some("tool"));
        package(&root.join("ws/src/z/older/tool"), Some("tool"));

        let path = PackagePath::new([root.join("nothing-here"), root.clone()]);
        let url = |p: &str| format!("package://{p}/meshes/link.stl");
        assert_eq!(path.resolve(&url("arm_description"), None), Ok(arm));
        assert_eq!(path.resolve(&url("hand_description"), None), Ok(hand));
        assert_eq!(path.resolve(&url("tool"), None), Ok(near));
        assert_eq!(path.resolve(&url("bare_description"), None), Ok(bare));
        for lost in ["gripper", "wrist", "base", "deep", "arm_ros"] {
            let error = path.resolve(&url(lost), None).unwrap_err();
            assert!(
                error.contains(&format!("no other package `{lost}`")),
                "{error}"
            );
        }
        // A package found whose file is missing is reported with its path.
        let error = path
            .resolve("package://arm_description/meshes/gone.stl", None)
            .unwrap_err();
        assert!(error.contains("arm_ros/meshes/gone.stl"), "{error}");
        std::fs::remove_dir_all(&root).unwrap();
    }
}
