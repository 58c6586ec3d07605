//! Forward kinematics of the test arm against transforms computed by hand
//! with rotation matrices (no quaternions, no nalgebra), limits, mimic
//! joints and every bad input.

mod files;

use gjkd_model::{JointError, Kinematics, KinematicsError, LimitMode};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

type M = [[f64; 3]; 3];

#[derive(Clone, Copy, Debug)]
struct T {
    r: M,
    t: [f64; 3],
}

fn mul(a: M, b: M) -> M {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn apply(a: M, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

const I: M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn rx(a: f64) -> M {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}
fn ry(a: f64) -> M {
    let (s, c) = a.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
fn rz(a: f64) -> M {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}
/// Rotation by `a` about the unit vector `k` (Rodrigues).
fn rot(k: [f64; 3], a: f64) -> M {
    let (s, c) = a.sin_cos();
    let mut m = [[0.0; 3]; 3];
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = c * I[i][j] + s * kx[i][j] + (1.0 - c) * k[i] * k[j];
        }
    }
    m
}
fn compose(a: T, b: T) -> T {
    let t = apply(a.r, b.t);
    T {
        r: mul(a.r, b.r),
        t: [t[0] + a.t[0], t[1] + a.t[1], t[2] + a.t[2]],
    }
}
fn tr(x: f64, y: f64, z: f64) -> T {
    T { r: I, t: [x, y, z] }
}
fn ro(r: M) -> T {
    T { r, t: [0.0; 3] }
}

/// The arm's link poses (URDF link order) by hand.
fn by_hand(base: T, q: [f64; 5]) -> Vec<T> {
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    let shoulder = compose(compose(base, tr(0.0, 0.0, 0.1)), ro(rz(q[0])));
    let upper = compose(compose(shoulder, tr(0.0, 0.0, 0.2)), ro(ry(q[1])));
    let rpy = T {
        r: mul(rz(0.3), mul(ry(0.2), rx(0.1))),
        t: [0.3, 0.0, 0.0],
    };
    let slider = compose(compose(upper, rpy), tr(q[2], 0.0, 0.0));
    let wrist = compose(compose(slider, tr(0.1, 0.0, 0.0)), ro(rz(q[3])));
    let hand = compose(
        wrist,
        T {
            r: ry(std::f64::consts::FRAC_PI_2),
            t: [0.0, 0.0, 0.05],
        },
    );
    let fl = compose(
        compose(hand, tr(0.0, 0.02, 0.0)),
        ro(rot([0.0, s2, s2], q[4])),
    );
    let fr = compose(
        compose(hand, tr(0.0, -0.02, 0.0)),
        ro(rot([0.0, -s2, s2], -q[4] + 0.1)),
    );
    vec![base, shoulder, upper, slider, wrist, hand, fl, fr]
}

fn assert_close(got: &Isometry3<f64>, want: &T, what: &str) {
    let r = got.rotation.to_rotation_matrix();
    for i in 0..3 {
        assert!(
            (got.translation.vector[i] - want.t[i]).abs() <= 1e-12,
            "{what}: translation {:?} vs {:?}",
            got.translation.vector,
            want.t
        );
        for j in 0..3 {
            assert!(
                (r[(i, j)] - want.r[i][j]).abs() <= 1e-12,
                "{what}: rotation {r} vs {:?}",
                want.r
            );
        }
    }
}

fn arm() -> Kinematics {
    Kinematics::from_urdf_str(files::ARM_URDF).unwrap()
}

#[test]
fn the_joint_order_is_the_moving_joints_in_file_order() {
    let k = arm();
    assert_eq!(k.joint_names(), ["j1", "j2", "j3", "j4", "j6"]);
    assert_eq!(k.dof(), 5);
    assert_eq!(
        k.link_names(),
        [
            "base", "shoulder", "upper", "slider", "wrist", "hand", "finger_l", "finger_r"
        ]
    );
}

#[test]
fn link_poses_match_hand_computed_transforms() {
    let k = arm();
    let configs = [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [0.5, -1.2, 0.15, 7.0, 0.3],
        [-2.9, 2.0, 0.2, -3.0, -1.0],
        [1.0, 0.25, 0.05, 100.0, 1.0],
    ];
    let bases = [
        Isometry3::identity(),
        Isometry3::from_parts(
            Translation3::new(1.0, -2.0, 0.5),
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.7),
        ),
    ];
    for base in &bases {
        let r = base.rotation.to_rotation_matrix();
        let hand_base = T {
            r: [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[(i, j)])),
            t: base.translation.vector.into(),
        };
        for q in configs {
            let got = k.link_poses(base, &q, LimitMode::Reject).unwrap();
            let want = by_hand(hand_base, q);
            for ((g, w), name) in got.iter().zip(&want).zip(k.link_names()) {
                assert_close(g, w, &format!("{name} at {q:?}"));
            }
        }
    }
}

#[test]
fn a_simple_configuration_has_the_expected_coordinates() {
    // At zero the arm stands up: shoulder at z 0.1, upper at 0.3, the
    // slider 0.3 out along x; with j2 at -pi/2 the upper arm points up, so
    // the slider is 0.3 above the upper link's origin.
    let k = arm();
    let p = k
        .link_poses(&Isometry3::identity(), &[0.0; 5], LimitMode::Reject)
        .unwrap();
    assert!((p[1].translation.vector - Vector3::new(0.0, 0.0, 0.1)).norm() < 1e-15);
    assert!((p[2].translation.vector - Vector3::new(0.0, 0.0, 0.3)).norm() < 1e-15);
    assert!((p[3].translation.vector - Vector3::new(0.3, 0.0, 0.3)).norm() < 1e-15);
    let up = -std::f64::consts::FRAC_PI_2;
    let p = k
        .link_poses(
            &Isometry3::identity(),
            &[0.0, up, 0.0, 0.0, 0.0],
            LimitMode::Reject,
        )
        .unwrap();
    assert!((p[3].translation.vector - Vector3::new(0.0, 0.0, 0.6)).norm() < 1e-15);
}

#[test]
fn limits_are_rejected_or_clamped() {
    let k = arm();
    let base = Isometry3::identity();
    let over = [0.0, 0.0, 0.25, 0.0, 0.0];
    assert_eq!(
        k.link_poses(&base, &over, LimitMode::Reject),
        Err(JointError::OutOfLimits {
            joint: "j3".into(),
            value: 0.25,
            lower: 0.0,
            upper: 0.2
        })
    );
    let clamped = k.link_poses(&base, &over, LimitMode::Clamp).unwrap();
    let at_limit = k
        .link_poses(&base, &[0.0, 0.0, 0.2, 0.0, 0.0], LimitMode::Reject)
        .unwrap();
    assert_eq!(clamped, at_limit);
    // A continuous joint has no limits.
    assert!(
        k.link_poses(&base, &[0.0, 0.0, 0.0, 1e6, 0.0], LimitMode::Reject)
            .is_ok()
    );
    // NaN is refused even when clamping.
    assert_eq!(
        k.link_poses(&base, &[0.0, f64::NAN, 0.0, 0.0, 0.0], LimitMode::Clamp),
        Err(JointError::NotFinite("j2".into()))
    );
    assert_eq!(
        k.link_poses(&base, &[0.0; 4], LimitMode::Reject),
        Err(JointError::WrongCount {
            expected: 5,
            got: 4
        })
    );
    let nan_base = Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert_eq!(
        k.link_poses(&nan_base, &[0.0; 5], LimitMode::Reject),
        Err(JointError::BadBase)
    );
}

#[test]
fn a_failed_request_leaves_the_buffer_alone() {
    let k = arm();
    let mut out = vec![Isometry3::translation(9.0, 9.0, 9.0); 3];
    let before = out.clone();
    let mut q = [0.0, 0.0, 0.5, 0.0, 0.0];
    let err = k.link_poses_into(&Isometry3::identity(), &mut q, LimitMode::Reject, &mut out);
    assert!(matches!(err, Err(JointError::OutOfLimits { .. })));
    assert_eq!(out, before);
    assert_eq!(q, [0.0, 0.0, 0.5, 0.0, 0.0]);
}

#[test]
fn positions_by_name_start_from_the_current_ones() {
    let k = arm();
    let q = k
        .positions_by_name(&[("j4", 2.0), ("j1", -1.0)], &[0.1, 0.2, 0.0, 0.3, 0.4])
        .unwrap();
    assert_eq!(q, [-1.0, 0.2, 0.0, 2.0, 0.4]);
    assert_eq!(
        k.positions_by_name(&[("j5", 0.0)], &[0.0; 5]),
        Err(JointError::UnknownJoint("j5".into()))
    );
    assert_eq!(
        k.positions_by_name(&[("j7", 0.0)], &[0.0; 5]),
        Err(JointError::UnknownJoint("j7".into()))
    );
}

fn two_links(joint: &str) -> String {
    format!(r#"<robot name="r"><link name="a"/><link name="b"/>{joint}</robot>"#)
}

#[test]
fn bad_trees_get_their_errors() {
    let bad = |text: &str| Kinematics::from_urdf_str(text).unwrap_err();
    assert!(matches!(
        bad("<robot name='r'><link"),
        KinematicsError::Malformed(_)
    ));
    assert!(matches!(
        bad(&two_links(r#"<joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>"#)),
        KinematicsError::UnknownLink { link, .. } if link == "c"
    ));
    assert!(matches!(bad(&two_links("")), KinematicsError::NotATree(m) if m.contains("several")));
    assert!(matches!(
        bad(&two_links(r#"<joint name="j" type="floating"><parent link="a"/><child link="b"/></joint>"#)),
        KinematicsError::UnsupportedJoint { kind, .. } if kind == "floating"
    ));
    assert!(matches!(
        bad(&two_links(r#"<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>"#)),
        KinematicsError::BadAxis(j) if j == "j"
    ));
    assert!(matches!(
        bad(&two_links(
            r#"<joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="1" upper="0" effort="1" velocity="1"/></joint>"#
        )),
        KinematicsError::BadLimits { .. }
    ));
    assert!(matches!(
        bad(r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
            <joint name="x" type="revolute"><parent link="a"/><child link="b"/><limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="y"/></joint>
            <joint name="y" type="revolute"><parent link="a"/><child link="c"/><limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="x"/></joint></robot>"#),
        KinematicsError::BadMimic { reason, .. } if reason.contains("cycle")
    ));
    assert!(matches!(
        bad(r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
            <joint name="x" type="fixed"><parent link="a"/><child link="b"/></joint>
            <joint name="y" type="revolute"><parent link="a"/><child link="c"/><limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="x"/></joint></robot>"#),
        KinematicsError::BadMimic { leader, reason, .. } if leader == "x" && reason.contains("fixed")
    ));
    assert_eq!(bad(r#"<robot name="r"></robot>"#), KinematicsError::NoLinks);
    assert_eq!(
        KinematicsError::NoLinks.to_string(),
        "the robot has no link"
    );
    assert!(matches!(
        bad(r#"<robot name="r"><link name="a"/><link name="a"/></robot>"#),
        KinematicsError::DuplicateName { what: "links", .. }
    ));
    assert!(matches!(
        bad(r#"<robot name="r"><link name="a"/><link name="b"/>
            <joint name="x" type="fixed"><parent link="a"/><child link="b"/></joint>
            <joint name="y" type="fixed"><parent link="b"/><child link="a"/></joint></robot>"#),
        KinematicsError::NotATree(_)
    ));
}

#[test]
fn a_mimic_joint_without_its_leader_moves_on_its_own() {
    // As in real descriptions (example-robot-data's psyonic hands), and as
    // MoveIt reads them: the joint is an ordinary one, with a warning.
    let urdf = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="first" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="orphan" type="prismatic"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="nope" multiplier="2"/></joint>
    </robot>"#;
    let k = Kinematics::from_urdf_str(urdf).unwrap();
    assert_eq!(k.joint_names(), ["first", "orphan"]);
    assert_eq!(k.warnings().len(), 1);
    assert!(
        k.warnings()[0].contains("`orphan` mimics `nope`"),
        "{:?}",
        k.warnings()
    );
    let p = k
        .link_poses(&Isometry3::identity(), &[0.25, -0.5], LimitMode::Reject)
        .unwrap();
    assert_eq!(p[2].translation.vector, Vector3::new(0.25, -0.5, 0.0));
    // Its own limits hold, not a leader's.
    assert!(matches!(
        k.link_poses(&Isometry3::identity(), &[0.0, 1.5], LimitMode::Reject),
        Err(JointError::OutOfLimits { joint, .. }) if joint == "orphan"
    ));
    // A joint following the orphan follows it as it would any leader.
    let chained = urdf.replace(
        "</robot>",
        r#"<link name="d"/><joint name="follower" type="prismatic"><parent link="a"/><child link="d"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="orphan" multiplier="-1"/></joint></robot>"#,
    );
    let k = Kinematics::from_urdf_str(&chained).unwrap();
    assert_eq!(k.joint_names(), ["first", "orphan"]);
    let p = k
        .link_poses(&Isometry3::identity(), &[0.0, 0.75], LimitMode::Reject)
        .unwrap();
    assert_eq!(p[3].translation.vector, Vector3::new(0.0, 0.0, -0.75));
}

#[test]
fn mimic_chains_compose() {
    let urdf = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
      <joint name="lead" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
        <limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
      <joint name="m1" type="prismatic"><parent link="a"/><child link="c"/><axis xyz="0 1 0"/>
        <limit lower="-10" upper="10" effort="1" velocity="1"/><mimic joint="lead" multiplier="2" offset="1"/></joint>
      <joint name="m2" type="prismatic"><parent link="a"/><child link="d"/><axis xyz="0 0 1"/>
        <limit lower="-10" upper="10" effort="1" velocity="1"/><mimic joint="m1" multiplier="3" offset="0.5"/></joint>
    </robot>"#;
    let k = Kinematics::from_urdf_str(urdf).unwrap();
    assert_eq!(k.joint_names(), ["lead"]);
    assert!(k.warnings().is_empty());
    let p = k
        .link_poses(&Isometry3::identity(), &[0.25], LimitMode::Reject)
        .unwrap();
    // m1 = 2 * 0.25 + 1 = 1.5; m2 = 3 * 1.5 + 0.5 = 5.
    assert_eq!(p[1].translation.vector, Vector3::new(0.25, 0.0, 0.0));
    assert_eq!(p[2].translation.vector, Vector3::new(0.0, 1.5, 0.0));
    assert_eq!(p[3].translation.vector, Vector3::new(0.0, 0.0, 5.0));
}
