//! Section 8 located exactly: for each obstacle of the paper's example,
//! the `s`-interval of its contact with the moving object, certified and
//! located to 1e-9, by continuous path requests
//! ([`PathMode::Continuous`], the paper's configuration variables linear
//! in `s`), beside the sampled sweep at T = 1 000.
//!
//! Each obstacle is asked alone (the others allowed), in one request of
//! two segments: the path from `s = 0` to 1 gives the first contact's
//! bracket, the same path backwards (the same poses, `s` run from 1 to 0)
//! the last contact's. Everything before
//! the first bracket and after the last is certified clear; an obstacle
//! with no contact is certified clear all along.

use std::io::Write;
use std::time::{Duration, Instant};

use gjkd_client::{Client, Item};
use gjkd_paper::{Motion, OBSTACLES};
use gjkd_proto::{PathMode, SceneKind, SceneRequest, SceneRow, scene_flags};

use crate::served_sweep::{DemoError, PathBuffers, Registered, path_sweep};

/// The width of every bracket, in `s`.
pub const BRACKET: f64 = 1e-9;

/// One obstacle's contact along the path.
#[derive(Clone, Copy, Debug, Default)]
pub struct Located {
    /// The first contact's bracket, `None` when certified clear all along.
    pub first: Option<(f64, f64)>,
    /// The last contact's bracket (in `s`, increasing).
    pub last: Option<(f64, f64)>,
}

/// Obstacle `i`'s first and last contact with `scene.moving`, margin 0,
/// in one request: the motion forth (segment 0) and back (segment 1).
fn contacts(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    i: usize,
) -> Result<Located, DemoError> {
    let mut items: Vec<Item> = scene
        .obstacles
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .map(|(_, &o)| Item::allow(scene.moving, o))
        .collect();
    for s in [0.0, 1.0, 0.0] {
        items.push(Item::set_pose(scene.moving, &motion.pose(s)).ending_step());
    }
    let mut request = SceneRequest::new(SceneKind::Within, scene.moving.raw());
    request.path = PathMode::Continuous as u32;
    request.flags |= scene_flags::LINEAR_QUATERNION;
    request.bracket = BRACKET;
    let mut rows = [SceneRow::default(); 2];
    request.max_rows = 2;
    let reply = crate::scene_call::query(client, &request, &items, &mut rows)
        .map_err(|e| DemoError::Check(format!("continuous path: {e}")))?;
    let mut located = Located::default();
    for row in &rows[..reply.total.min(2) as usize] {
        if row.b != scene.obstacles[i].raw() || row.result.lower > 0.0 {
            return Err(DemoError::Check(format!(
                "obstacle {}: unexpected contact row {row:?}",
                i + 1
            )));
        }
        match row.step {
            0 => located.first = Some((row.s_lo, row.s_hi)),
            // Backwards, `s` runs from 1 to 0.
            _ => located.last = Some((1.0 - row.s_hi, 1.0 - row.s_lo)),
        }
    }
    Ok(located)
}

/// Every obstacle's contact interval; returns them and the time taken.
///
/// # Errors
/// A failed request.
pub(crate) fn locate(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
) -> Result<([Located; OBSTACLES], Duration), DemoError> {
    let start = Instant::now();
    let mut out = [Located::default(); OBSTACLES];
    for (i, located) in out.iter_mut().enumerate() {
        *located = contacts(client, motion, scene, i)?;
    }
    Ok((out, start.elapsed()))
}

/// Prints the located intervals beside the sampled sweep at `t` steps
/// (one path request, every step).
///
/// # Errors
/// A failed request.
pub(crate) fn print(
    out: &mut impl Write,
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    t: usize,
) -> Result<(), DemoError> {
    // The sampled sweep first: the first scene request of a connection
    // also opens its scene port, which is no part of either answer. Then
    // each is timed again, alternately, and the faster of three kept.
    let mut buf = PathBuffers::new(t);
    let mut sampled = path_sweep(client, motion, scene, t, PathMode::EveryStep, &mut buf)
        .map_err(|e| DemoError::Check(format!("path request: {e}")))?;
    let (mut located, mut exact_time) = locate(client, motion, scene)?;
    for _ in 0..2 {
        let again = path_sweep(client, motion, scene, t, PathMode::EveryStep, &mut buf)
            .map_err(|e| DemoError::Check(format!("path request: {e}")))?;
        if again.elapsed < sampled.elapsed {
            sampled = again;
        }
        let (l, e) = locate(client, motion, scene)?;
        if e < exact_time {
            (located, exact_time) = (l, e);
        }
    }
    let _ = writeln!(
        out,
        "Contact intervals, margin 0: the sampled sweep at T = {t} (one path request, {:.3} ms)\n\
         against continuous path requests, certified, brackets at most {BRACKET:e} wide\n\
         ({} requests, {:.3} ms in all; each the fastest of three). Certified clear before\n\
         the entry bracket and after the exit bracket; Canny's exact method took 11.6 s\n\
         for the paper's example, and gives no distances.\n",
        sampled.elapsed.as_secs_f64() * 1e3,
        OBSTACLES,
        exact_time.as_secs_f64() * 1e3,
    );
    let _ = writeln!(
        out,
        "{:>4} {:>22} {:>45} {:>45}",
        "K", "sampled (T steps)", "entry s in [lo, hi]", "exit s in [lo, hi]"
    );
    for (i, l) in located.iter().enumerate() {
        let steps: Vec<usize> = (0..=t)
            .filter(|&k| sampled.hits[k] & (1 << i) != 0)
            .collect();
        let sampled_text = match (steps.first(), steps.last()) {
            (Some(a), Some(b)) => {
                format!("[{:.3}, {:.3}]", *a as f64 / t as f64, *b as f64 / t as f64)
            }
            _ => "none".to_owned(),
        };
        let bracket = |b: Option<(f64, f64)>| {
            b.map_or("certified clear".to_owned(), |(lo, hi)| {
                format!("[{lo:.12}, {hi:.12}]")
            })
        };
        let _ = writeln!(
            out,
            "{:>4} {sampled_text:>22} {:>45} {:>45}",
            format!("K{}", i + 1),
            bracket(l.first),
            bracket(l.last),
        );
    }
    let _ = writeln!(out);
    Ok(())
}
