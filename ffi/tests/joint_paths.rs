//! `gjkd_path_joints`: scene questions along joint positions answer the
//! distances forward kinematics gives in closed form, move nothing on the
//! server, and refuse bad positions naming their step and joint.
// Joint paths need robots: the library's `robots` feature.
#![cfg(feature = "robots")]

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_path_question::*;
use gjkd_status::*;

/// A rod of radius 0.1 and length 1 hanging from the origin along -z,
/// swung about y by one joint limited to [-2, 2].
const PENDULUM: &str = r#"<robot name="pendulum">
  <link name="mount"/>
  <link name="rod"><collision><origin xyz="0 0 -0.5"/>
    <geometry><cylinder radius="0.1" length="1"/></geometry></collision></link>
  <joint name="swing" type="revolute"><parent link="mount"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>"#;

/// Centre of the ball the rod swings above.
const BALL: [f64; 3] = [0.0, 0.0, -3.0];
const BALL_RADIUS: f64 = 0.5;

fn message() -> String {
    // SAFETY: never NULL, alive until the next call on this thread.
    unsafe { CStr::from_ptr(gjkd_last_error()) }
        .to_string_lossy()
        .into_owned()
}

#[track_caller]
fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{}", message());
}

#[track_caller]
fn fails(status: gjkd_status, want: gjkd_status, code: u32, words: &str) {
    let msg = message();
    assert_eq!(status, want, "{msg}");
    assert_eq!(gjkd_last_error_code(), code, "{msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

/// The distance from the ball to the rod swung by `q` while the ball is
/// below the rod's mount end (the nearest point on the rim of the rod's
/// top disk, or on its side when the ball is beside it): the rod's axis is
/// `u = (-sin q, 0, -cos q)` from the origin.
fn rod_to_ball(q: f64) -> f64 {
    let u = [-q.sin(), 0.0, -q.cos()];
    let t: f64 = (0..3).map(|i| BALL[i] * u[i]).sum();
    let radial: f64 = (0..3)
        .map(|i| (BALL[i] - t * u[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let axial = if t < 0.0 {
        -t
    } else if t > 1.0 {
        t - 1.0
    } else {
        0.0
    };
    (axial.powi(2) + (radial - 0.1).max(0.0).powi(2)).sqrt() - BALL_RADIUS
}

struct Scene {
    c: *mut gjkd_client,
    robot: *mut gjkd_robot,
    rod: gjkd_id,
    ball: gjkd_id,
}

impl Scene {
    fn new(server: &Server) -> Self {
        let service = CString::new(server.service.clone()).unwrap();
        let urdf = CString::new(PENDULUM).unwrap();
        let (mut c, mut robot, mut rod, mut ball) = (null_mut(), null_mut(), 0, 0);
        let centre = gjkd_pose {
            translation: BALL,
            rotation: [0.0, 0.0, 0.0, 1.0],
        };
        // SAFETY: valid pointers, live handles.
        unsafe {
            ok(gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c));
            ok(gjkd_register_robot_text(
                c,
                c"pendulum".as_ptr(),
                urdf.as_ptr(),
                null(),
                null(),
                null(),
                null(),
                &mut robot,
            ));
            ok(gjkd_robot_link_id(robot, c"rod".as_ptr(), &mut rod));
            ok(gjkd_register_sphere(
                c,
                BALL_RADIUS,
                null(),
                &centre,
                &mut ball,
            ));
        }
        Scene {
            c,
            robot,
            rod,
            ball,
        }
    }

    fn group(&self) -> gjkd_group {
        let mut id = 0;
        // SAFETY: a live robot.
        ok(unsafe { gjkd_robot_info(self.robot, &mut id, null_mut(), null_mut()) });
        gjkd_group {
            id,
            members: null(),
            member_count: 0,
            allowed: null(),
            allowed_count: 0,
        }
    }

    /// Runs a joint path; the status, rows and summary.
    fn path(
        &self,
        question: gjkd_path_question,
        margin: f64,
        positions: &[f64],
        options: Option<&gjkd_scene_options>,
    ) -> (gjkd_status, Vec<gjkd_scene_row>, gjkd_scene_summary) {
        let mut rows = vec![gjkd_scene_row::default(); 16];
        let mut summary = gjkd_scene_summary::default();
        let group = self.group();
        // SAFETY: valid pointers; rows has the room it says.
        let status = unsafe {
            gjkd_path_joints(
                self.c,
                &group,
                question as u32,
                margin,
                self.robot,
                positions.as_ptr(),
                positions.len(),
                options.map_or(null(), |o| o as *const _),
                rows.as_mut_ptr(),
                rows.len(),
                &mut summary,
            )
        };
        rows.truncate(summary.written);
        (status, rows, summary)
    }

    /// The rod's distance to the ball at their stored poses.
    fn stored_distance(&self) -> f64 {
        let mut a = gjkd_answer::default();
        // SAFETY: valid pointers.
        ok(unsafe { gjkd_distance(self.c, self.rod, self.ball, null(), null(), null(), &mut a) });
        a.distance
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: handles made by Scene::new, freed once.
        unsafe {
            gjkd_robot_free(self.robot);
            gjkd_close(self.c);
        }
    }
}

#[test]
fn clearance_along_joint_positions_matches_the_closed_form() {
    let server = Server::start("ffi-joint-path", &["--no-persist"]);
    let s = Scene::new(&server);
    let level = std::f64::consts::FRAC_PI_2;
    // The robot's stored position: level, 2.4 from the ball.
    // SAFETY: a live handle and robot.
    ok(unsafe { gjkd_set_joints(s.c, s.robot, [level].as_ptr(), 1, null(), false) });
    assert!((s.stored_distance() - 2.4).abs() <= 1e-9);
    let qs = [0.0, 0.5, level, -1.0, 2.0];
    let (status, rows, summary) = s.path(GJKD_PATH_CLEARANCE, 0.0, &qs, None);
    ok(status);
    assert_eq!((summary.steps, summary.written), (5, 5));
    assert!((rod_to_ball(0.0) - 1.5).abs() <= 1e-12, "the closed form");
    for (row, (step, q)) in rows.iter().zip(qs.iter().enumerate()) {
        assert_eq!((row.a, row.b, row.step), (s.rod, s.ball, step as u32));
        assert_eq!(row.error, 0);
        let want = rod_to_ball(*q);
        assert!(
            (row.answer.distance - want).abs() <= 1e-9,
            "step {step}, q {q}: {} vs {want}",
            row.answer.distance
        );
        assert!(row.answer.lower <= want + 1e-12 && want <= row.answer.upper + 1e-12);
    }
    // Nothing moved on the server.
    assert!((s.stored_distance() - 2.4).abs() <= 1e-9);
}

#[test]
fn first_hit_along_joint_positions_names_its_step() {
    let server = Server::start("ffi-joint-hit", &["--no-persist"]);
    let s = Scene::new(&server);
    let level = std::f64::consts::FRAC_PI_2;
    let qs = [level, 1.0, 0.2, 0.0, 0.0];
    // Within 1.6 first at q = 0.2 (about 1.52 from the ball).
    assert!(rod_to_ball(1.0) > 1.6 && rod_to_ball(0.2) < 1.6);
    let (status, rows, summary) = s.path(GJKD_PATH_FIRST_HIT, 1.6, &qs, None);
    ok(status);
    assert_eq!(summary.first_hit, 2, "{summary:?}");
    assert_eq!(rows.len(), 1);
    assert_eq!((rows[0].step, rows[0].b), (2, s.ball));
    assert!((rows[0].answer.distance - rod_to_ball(0.2)).abs() <= 1e-9);
    // No step within 1.0: no hit.
    let (status, rows, summary) = s.path(GJKD_PATH_FIRST_HIT, 1.0, &qs, None);
    ok(status);
    assert_eq!((summary.first_hit, rows.len()), (u32::MAX, 0));
}

#[test]
fn bad_positions_and_arguments_are_refused_before_sending() {
    let server = Server::start("ffi-joint-errors", &["--no-persist"]);
    let s = Scene::new(&server);
    let (status, ..) = s.path(GJKD_PATH_CLEARANCE, 0.0, &[0.0, 2.5], None);
    fails(
        status,
        GJKD_ERR_INVALID_ARGUMENT,
        gjkd_error_code::GJKD_CODE_OUT_OF_LIMITS as u32,
        "positions of step 1",
    );
    assert!(message().contains("swing"), "{}", message());
    let (status, ..) = s.path(GJKD_PATH_CLEARANCE, 0.0, &[f64::NAN], None);
    fails(
        status,
        GJKD_ERR_INVALID_ARGUMENT,
        gjkd_error_code::GJKD_CODE_NON_FINITE_POSE as u32,
        "positions of step 0",
    );
    // Clamped, 2.5 answers as the limit 2.
    let mut clamp = gjkd_scene_options_default();
    clamp.clamp = true;
    let (status, rows, _) = s.path(GJKD_PATH_CLEARANCE, 0.0, &[2.5], Some(&clamp));
    ok(status);
    assert!((rows[0].answer.distance - rod_to_ball(2.0)).abs() <= 1e-9);

    let group = s.group();
    let mut rows = [gjkd_scene_row::default(); 4];
    let mut summary = gjkd_scene_summary::default();
    let q = [0.0];
    // SAFETY (each call): valid pointers or the NULL being tested.
    unsafe {
        let call = |robot: *const gjkd_robot, positions: *const f64, steps: usize, question| {
            let mut rows = [gjkd_scene_row::default(); 4];
            let mut summary = gjkd_scene_summary::default();
            gjkd_path_joints(
                s.c,
                &group,
                question,
                0.0,
                robot,
                positions,
                steps,
                null(),
                rows.as_mut_ptr(),
                4,
                &mut summary,
            )
        };
        let clearance = GJKD_PATH_CLEARANCE as u32;
        fails(
            call(null(), q.as_ptr(), 1, clearance),
            GJKD_ERR_NULL_POINTER,
            0,
            "robot is NULL",
        );
        fails(
            call(s.robot, null(), 1, clearance),
            GJKD_ERR_NULL_POINTER,
            0,
            "positions is NULL",
        );
        fails(
            call(s.robot, q.as_ptr(), 0, clearance),
            GJKD_ERR_INVALID_ARGUMENT,
            0,
            "a path needs a step",
        );
        fails(
            call(s.robot, q.as_ptr(), usize::MAX, clearance),
            GJKD_ERR_INVALID_ARGUMENT,
            0,
            "larger than any array",
        );
        fails(
            call(s.robot, q.as_ptr(), 1, 7),
            GJKD_ERR_INVALID_ARGUMENT,
            0,
            "no gjkd_path_question",
        );
        fails(
            gjkd_path_joints(
                s.c,
                null(),
                clearance,
                0.0,
                s.robot,
                q.as_ptr(),
                1,
                null(),
                rows.as_mut_ptr(),
                4,
                &mut summary,
            ),
            GJKD_ERR_NULL_POINTER,
            0,
            "group is NULL",
        );
    }
}
