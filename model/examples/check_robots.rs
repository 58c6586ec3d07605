//! Checks robot descriptions against two independent readings: link poses
//! against the `k` crate's forward kinematics at random configurations, and
//! each link's shape against its URDF collision elements as `urdf-rs`
//! reads them (mesh vertices with their origin and scale, boxes, spheres,
//! cylinders, capsules), by comparing support values in random directions:
//! equal support values in every direction mean the same convex hull.
//!
//! ```sh
//! cargo run --release -p gjkd-model --example check_robots -- FOLDER_OR_URDF... [--packages DIR]...
//! ```
//!
//! A folder is searched for `*.urdf` files. Prints one line per robot and
//! exits non-zero if any pose or support value differs by more than 1e-12
//! (poses, in metres and rotation entries) or 1e-9 of the link's size
//! (support values); a robot that either side cannot read is reported and
//! skipped.

use std::path::{Path, PathBuf};

use gjk::{Convex, Shape};
use gjkd_model::{Kinematics, LimitMode, Mesh, PackagePath, RobotModel};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Random configurations per robot, and directions per link.
const CONFIGURATIONS: usize = 50;
const DIRECTIONS: usize = 200;

/// A small xorshift generator.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn direction(&mut self) -> Vector3<f64> {
        Vector3::new(
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
        )
        .normalize()
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut inputs, mut packages) = (Vec::new(), Vec::new());
    let mut args = std::env::args_os().skip(1);
    while let Some(arg) = args.next() {
        if arg == "--packages" {
            packages.push(PathBuf::from(
                args.next().ok_or("--packages needs a folder")?,
            ));
        } else {
            inputs.push(PathBuf::from(arg));
        }
    }
    if inputs.is_empty() {
        return Err("usage: check_robots FOLDER_OR_URDF... [--packages DIR]...".into());
    }
    let packages = PackagePath::with_env(packages);
    let mut urdfs = Vec::new();
    for input in &inputs {
        find_urdfs(input, &mut urdfs)?;
    }
    urdfs.sort();
    let (mut checked, mut failed) = (0, 0);
    for urdf in &urdfs {
        match check(urdf, &packages) {
            Ok(report) => {
                checked += 1;
                let bad = report.pose > 1e-12 || report.support > 1e-9;
                failed += usize::from(bad);
                println!(
                    "{} {}: {} links with shapes, dof {}, pose difference {:.1e}, support difference {:.1e} of size{}",
                    if bad { "DIFFERS" } else { "agrees " },
                    urdf.display(),
                    report.links,
                    report.dof,
                    report.pose,
                    report.support,
                    report.note
                );
            }
            Err(e) => println!("skipped {}: {e}", urdf.display()),
        }
    }
    println!("{checked} robots checked, {failed} differ");
    if failed > 0 {
        std::process::exit(1);
    }
    Ok(())
}

/// Adds `path` if it is a file, or the `*.urdf` files below it.
fn find_urdfs(path: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    if !path.is_dir() {
        out.push(path.to_path_buf());
        return Ok(());
    }
    for entry in std::fs::read_dir(path)? {
        let entry = entry?.path();
        if entry.is_dir() {
            find_urdfs(&entry, out)?;
        } else if entry
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
        {
            out.push(entry);
        }
    }
    Ok(())
}

/// What [`check`] found for one robot.
struct Report {
    links: usize,
    dof: usize,
    /// The largest pose difference from `k`.
    pose: f64,
    /// The largest support difference, relative to the link's size.
    support: f64,
    /// Joints `k` could not follow, if any.
    note: String,
}

fn check(urdf: &Path, packages: &PackagePath) -> Result<Report, Box<dyn std::error::Error>> {
    let model = RobotModel::load(urdf, packages)?;
    let described = urdf_rs::read_file(urdf).map_err(|e| format!("urdf-rs: {e}"))?;
    let chain = k_chain(urdf)?;
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (pose, refused) = pose_difference(&model.kinematics, &chain, &mut rng)?;
    let mut support: f64 = 0.0;
    let mut links = 0;
    for link in &described.links {
        let ours = model
            .links
            .iter()
            .find(|l| l.name == link.name)
            .ok_or_else(|| format!("link {} is missing", link.name))?;
        let elements = collision_elements(link, urdf, packages)?;
        match (&ours.shape, elements.is_empty()) {
            (None, true) => continue,
            (Some(shape), false) => {
                links += 1;
                support = support.max(support_difference(shape, &elements, &mut rng));
            }
            _ => return Err(format!("link {}: shape and elements disagree", link.name).into()),
        }
    }
    let note = if refused > 0 {
        format!(" ({refused} positions k refused by its own limits, not compared)")
    } else {
        String::new()
    };
    Ok(Report {
        links,
        dof: model.kinematics.dof(),
        pose,
        support,
        note,
    })
}

/// `k`'s chain of the URDF, or why not: its error, or its panic (it
/// panics on some descriptions, a mimic joint naming a joint it lacks),
/// caught with the message kept off the terminal.
fn k_chain(urdf: &Path) -> Result<k::Chain<f64>, String> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let chain = std::panic::catch_unwind(|| k::Chain::<f64>::from_urdf_file(urdf));
    std::panic::set_hook(hook);
    match chain {
        Ok(Ok(chain)) => Ok(chain),
        Ok(Err(e)) => Err(format!("k: {e}")),
        Err(_) => Err("k panicked reading it".to_owned()),
    }
}

/// The largest difference of any link pose entry from `k`'s, over random
/// configurations within the limits (a continuous joint within a turn),
/// and the number of configurations `k` refused (it also holds continuous
/// and mimic joints to limits, which a URDF does not require); those are
/// left out.
fn pose_difference(
    ours: &Kinematics,
    chain: &k::Chain<f64>,
    rng: &mut Rng,
) -> Result<(f64, usize), Box<dyn std::error::Error>> {
    let (mut worst, mut refused): (f64, usize) = (0.0, 0);
    for _ in 0..CONFIGURATIONS {
        let q: Vec<f64> = ours
            .moving_joints()
            .map(|j| {
                let turn = std::f64::consts::TAU;
                rng.uniform(j.lower.max(-turn), j.upper.min(turn))
            })
            .collect();
        let poses = ours.link_poses(&Isometry3::identity(), &q, LimitMode::Reject)?;
        let mut accepted = true;
        for (j, &qj) in ours.moving_joints().zip(&q) {
            let node = chain.find(&j.name).ok_or("a joint k does not have")?;
            accepted &= node.set_joint_position(qj).is_ok();
        }
        if !accepted {
            refused += 1;
            continue;
        }
        chain.update_transforms();
        for joint in ours.joints() {
            let node = chain.find(&joint.name).ok_or("a joint k does not have")?;
            let theirs = node.world_transform().ok_or("k has no transform")?;
            let mine = &poses[joint.child];
            // k has its own nalgebra: compared entry by entry.
            let (t, r) = (
                theirs.translation.vector,
                theirs.rotation.to_rotation_matrix(),
            );
            let mr = mine.rotation.to_rotation_matrix();
            for a in 0..3 {
                worst = worst.max((mine.translation.vector[a] - t[a]).abs());
                for b in 0..3 {
                    worst = worst.max((mr[(a, b)] - r[(a, b)]).abs());
                }
            }
        }
    }
    Ok((worst, refused))
}

/// A collision element's support function in the link frame, and its
/// extent from the link's origin.
type Element = (Box<dyn Fn(&Vector3<f64>) -> f64>, f64);

/// The support functions of `link`'s collision elements, read by `urdf-rs`.
fn collision_elements(
    link: &urdf_rs::Link,
    urdf: &Path,
    packages: &PackagePath,
) -> Result<Vec<Element>, Box<dyn std::error::Error>> {
    let mut out: Vec<Element> = Vec::new();
    for c in &link.collision {
        let (xyz, rpy) = (c.origin.xyz, c.origin.rpy);
        let at = Isometry3::from_parts(
            Translation3::new(xyz[0], xyz[1], xyz[2]),
            UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
        );
        let reach = at.translation.vector.norm();
        // Each primitive's support in its own frame, `d` turned into it.
        let local = move |d: &Vector3<f64>| at.rotation.inverse() * d;
        let shift = move |d: &Vector3<f64>| at.translation.vector.dot(d);
        match &c.geometry {
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let path = packages.resolve(filename, urdf.parent())?;
                let scale = scale.map_or([1.0; 3], |s| [s[0], s[1], s[2]]);
                let points: Vec<Point3<f64>> = Mesh::load(&path, scale)?
                    .vertices
                    .iter()
                    .map(|p| at * p)
                    .collect();
                let extent = points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
                let support = move |d: &Vector3<f64>| {
                    points
                        .iter()
                        .map(|p| p.coords.dot(d))
                        .fold(f64::NEG_INFINITY, f64::max)
                };
                out.push((Box::new(support), extent));
            }
            urdf_rs::Geometry::Box { size } => {
                let h = Vector3::new(size[0], size[1], size[2]) / 2.0;
                let support = move |d: &Vector3<f64>| shift(d) + h.dot(&local(d).abs());
                out.push((Box::new(support), reach + h.norm()));
            }
            urdf_rs::Geometry::Sphere { radius } => {
                let r = *radius;
                out.push((Box::new(move |d| shift(d) + r * d.norm()), reach + r));
            }
            urdf_rs::Geometry::Cylinder { radius, length } => {
                let (r, h) = (*radius, length / 2.0);
                let support = move |d: &Vector3<f64>| {
                    let e = local(d);
                    shift(d) + r * e.xy().norm() + h * e.z.abs()
                };
                out.push((Box::new(support), reach + r + h));
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                let (r, h) = (*radius, length / 2.0);
                let support =
                    move |d: &Vector3<f64>| shift(d) + r * d.norm() + h * local(d).z.abs();
                out.push((Box::new(support), reach + r + h));
            }
        }
    }
    Ok(out)
}

/// The largest difference between `shape`'s support value and the
/// elements' greatest, over random unit directions, relative to the
/// elements' extent.
fn support_difference(shape: &Shape, elements: &[Element], rng: &mut Rng) -> f64 {
    let size = elements
        .iter()
        .map(|e| e.1)
        .fold(f64::MIN_POSITIVE, f64::max);
    let mut worst: f64 = 0.0;
    for _ in 0..DIRECTIONS {
        let d = rng.direction();
        let want = elements
            .iter()
            .map(|e| (e.0)(&d))
            .fold(f64::NEG_INFINITY, f64::max);
        let got = match shape {
            Shape::Convex(c) => convex_support(c, &Isometry3::identity(), &d),
            Shape::Compound(c) => c
                .pieces()
                .iter()
                .map(|(offset, piece)| convex_support(piece, offset, &d))
                .fold(f64::NEG_INFINITY, f64::max),
        };
        worst = worst.max((got - want).abs() / size);
    }
    worst
}

/// The support value of `c` placed at `offset`, in direction `d`: its
/// vertices' greatest (a cylinder's closed form), plus its radius.
fn convex_support(c: &Convex, offset: &Isometry3<f64>, d: &Vector3<f64>) -> f64 {
    let e = offset.rotation.inverse() * d;
    let core = match c.cylinder_dimensions() {
        Some((r, h)) => c.centroid().coords.dot(&e) + r * e.xy().norm() + h * e.z.abs(),
        None => c
            .vertices()
            .iter()
            .map(|v| v.coords.dot(&e))
            .fold(f64::NEG_INFINITY, f64::max),
    };
    core + c.radius() + offset.translation.vector.dot(d)
}
