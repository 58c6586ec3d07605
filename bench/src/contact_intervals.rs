//! Section 8 located exactly: for each obstacle of the paper's example,
//! the `s`-interval of its contact with the moving object, certified and
//! located to 1e-9, by continuous path requests
//! ([`PathMode::Continuous`], the paper's configuration variables linear
//! in `s`), beside the sampled sweep at T = 1 000.
//!
//! Each obstacle is asked alone (the others allowed): the path from `s = 0`
//! to 1 gives the first contact's bracket, the same path backwards (the
//! same poses, `s` run from 1 to 0) the last contact's. Everything before
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

/// The first contact of `scene.moving` with obstacle `i` along the motion,
/// or along it backwards, margin 0: its bracket in this request's `s`.
fn first_contact(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    i: usize,
    backwards: bool,
) -> Result<Option<(f64, f64)>, DemoError> {
    let (from, to) = if backwards { (1.0, 0.0) } else { (0.0, 1.0) };
    let mut items: Vec<Item> = scene
        .obstacles
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .map(|(_, &o)| Item::allow(scene.moving, o))
        .collect();
    items.push(Item::set_pose(scene.moving, &motion.pose(from)).ending_step());
    items.push(Item::set_pose(scene.moving, &motion.pose(to)).ending_step());
    let mut request = SceneRequest::new(SceneKind::Within, scene.moving.raw());
    request.path = PathMode::Continuous as u32;
    request.flags |= scene_flags::LINEAR_QUATERNION;
    request.bracket = BRACKET;
    let mut rows = [SceneRow::default(); 1];
    request.max_rows = 1;
    let reply = crate::scene_call::query(client, &request, &items, &mut rows)
        .map_err(|e| DemoError::Check(format!("continuous path: {e}")))?;
    if reply.total == 0 {
        return Ok(None);
    }
    let row = rows[0];
    if row.b != scene.obstacles[i].raw() || row.result.lower > 0.0 {
        return Err(DemoError::Check(format!(
            "obstacle {}: unexpected contact row {row:?}",
            i + 1
        )));
    }
    Ok(Some((row.s_lo, row.s_hi)))
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
        located.first = first_contact(client, motion, scene, i, false)?;
        if located.first.is_some() {
            located.last =
                first_contact(client, motion, scene, i, true)?.map(|(lo, hi)| (1.0 - hi, 1.0 - lo));
        }
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
    let (located, exact_time) = locate(client, motion, scene)?;
    let mut buf = PathBuffers::new(t);
    let sampled = path_sweep(client, motion, scene, t, PathMode::EveryStep, &mut buf)
        .map_err(|e| DemoError::Check(format!("path request: {e}")))?;
    let _ = writeln!(
        out,
        "Contact intervals, margin 0: the sampled sweep at T = {t} (one path request, {:.3} ms)\n\
         against continuous path requests, certified, brackets at most {BRACKET:e} wide\n\
         ({} requests, {:.3} ms in all). Certified clear before the entry bracket and after\n\
         the exit bracket; Canny's exact method took 11.6 s for the paper's example, no distances.\n",
        sampled.elapsed.as_secs_f64() * 1e3,
        located
            .iter()
            .map(|l| 1 + usize::from(l.first.is_some()))
            .sum::<usize>(),
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
