//! The package search path read from the environment. One test in its own
//! binary: it sets environment variables, which no other thread reads.

use std::path::PathBuf;

use gjkd_model::{PACKAGE_PATH_ENV, PackagePath};

#[test]
fn package_folders_come_from_gjkd_ros_and_ament_variables_in_order() {
    let root = std::env::temp_dir().join(format!("gjkd-model-env-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    // A ROS 2 install prefix keeps a package's files in `share/NAME`.
    let installed = root.join("install/share/arm_description/meshes/link.stl");
    std::fs::create_dir_all(installed.parent().unwrap()).unwrap();
    std::fs::write(&installed, b"solid x\nendsolid x\n").unwrap();
    let join = |dirs: &[PathBuf]| std::env::join_paths(dirs).unwrap();
    // SAFETY: this binary's only test; nothing else reads the environment.
    unsafe {
        std::env::set_var(PACKAGE_PATH_ENV, join(&[root.join("gjkd")]));
        std::env::set_var(
            "ROS_PACKAGE_PATH",
            join(&[root.join("ros1"), root.join("ros2")]),
        );
        std::env::set_var(
            "AMENT_PREFIX_PATH",
            join(&[root.join("missing"), root.join("install")]),
        );
    }
    let path = PackagePath::with_env([root.join("given")]);
    assert_eq!(
        path.dirs,
        [
            root.join("given"),
            root.join("gjkd"),
            root.join("ros1"),
            root.join("ros2"),
            root.join("missing/share"),
            root.join("install/share"),
        ]
    );
    assert_eq!(
        path.resolve("package://arm_description/meshes/link.stl", None),
        Ok(installed)
    );
    std::fs::remove_dir_all(&root).unwrap();
}
