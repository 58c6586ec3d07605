//! Continuous paths: is the whole motion between consecutive steps clear?
//!
//! [`SceneQuery::continuous`] after [`Client::within`] asks every pose of
//! the motion, not samples of it (see
//! [`PathMode::Continuous`](gjkd_proto::PathMode::Continuous)): a segment
//! with no [`Contact`] is certified clear, a segment with one has its first
//! contact bracketed in `s` to the width asked. [`Client::edge_contact`] is
//! a planner's edge check in one call.

use gjkd_proto::{PathMode, SceneRow, scene_flags};

use super::{SceneQuery, Steps};
#[cfg(feature = "robots")]
use crate::RobotHandle;
#[cfg(feature = "robots")]
use crate::SceneError;
use crate::{Answer, Client, ErrorCode, ObjectId};

/// The first contact along one segment of a continuous path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The segment: from step `segment` to step `segment + 1`.
    pub segment: u32,
    /// The group's object.
    pub a: ObjectId,
    /// The other object.
    pub b: ObjectId,
    /// Every pose of the segment before this `s` is certified clear.
    pub s_lo: f64,
    /// The pose at this `s` is within the margin: `answer` is the pair's
    /// there.
    pub s_hi: f64,
    /// The pair's answer at `s_hi` (its interval reaches the margin), or
    /// its own error.
    pub answer: Result<Answer, ErrorCode>,
}

impl From<&SceneRow> for Contact {
    fn from(row: &SceneRow) -> Self {
        Contact {
            segment: row.step,
            a: ObjectId::from_raw(row.a),
            b: ObjectId::from_raw(row.b),
            s_lo: row.s_lo,
            s_hi: row.s_hi,
            answer: row.result.answer_with(Some(&row.gradient)),
        }
    }
}

impl Default for Contact {
    /// A placeholder for a buffer of contacts: segment 0, ids 0, no answer.
    fn default() -> Self {
        Contact {
            segment: 0,
            a: ObjectId::from_raw(0),
            b: ObjectId::from_raw(0),
            s_lo: 0.0,
            s_hi: 0.0,
            answer: Err(ErrorCode::Malformed),
        }
    }
}

impl<'a> SceneQuery<'_, 'a> {
    /// [`Client::within`] along the whole motion between consecutive steps
    /// of `steps` (joint positions linear between them; a rigid object's
    /// translation linear and its rotation along the shortest arc): for
    /// each segment with a contact, one row, its first contact bracketed in
    /// `[s_lo, s_hi]` at most `bracket` wide ([`Contact`]); no row for a
    /// segment certified clear. Read the rows with
    /// [`SceneQuery::into_contacts`].
    pub fn continuous(mut self, steps: Steps<'a>, bracket: f64) -> Self {
        self.request.path = PathMode::Continuous as u32;
        self.request.bracket = bracket;
        self.steps = Some(steps);
        self
    }

    /// A continuous path's rigid objects turn with their quaternions'
    /// components linear in `s`, renormalised (the configuration variables
    /// of the GJK paper's Section 8), not along the shortest arc.
    pub fn linear_quaternions(mut self) -> Self {
        self.request.flags |= scene_flags::LINEAR_QUATERNION;
        self
    }

    /// Runs a continuous path and decodes its rows into `contacts`, one per
    /// segment that touches, in segment order.
    ///
    /// # Errors
    /// As [`SceneQuery::into_rows`], and
    /// [`SceneError::InvalidOptions`](crate::SceneError::InvalidOptions)
    /// for a bracket that is not a finite number `> 0`,
    /// [`SceneError::Malformed`](crate::SceneError::Malformed) for fewer
    /// than two steps, a segment along which nothing moves, or a question
    /// other than [`Client::within`].
    pub fn into_contacts(
        self,
        contacts: &mut [Contact],
    ) -> Result<super::SceneSummary, crate::SceneError> {
        let max_rows = contacts.len();
        self.run(max_rows, |got| {
            for (out, row) in contacts.iter_mut().zip(got) {
                *out = Contact::from(row);
            }
        })
    }
}

impl Client {
    /// A planner's edge check in one request: is the straight joint-space
    /// motion of `robot` from `from` to `to` (its joint order) clear of
    /// everything else by more than `margin` at every pose, its allowed
    /// pairs left out? `None` when certified clear, else the first contact,
    /// bracketed to `bracket` in `s`.
    ///
    /// ```no_run
    /// # use gjkd_client::{Client, PackagePath};
    /// # use nalgebra::Isometry3;
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// # let mut client = Client::connect("gjkd")?;
    /// # let urdf = std::path::Path::new("panda.urdf");
    /// let panda = client.register_robot("panda", urdf, None, &PackagePath::default(),
    ///     &Isometry3::identity())?;
    /// let (q0, q1) = (vec![0.0; 8], vec![0.5; 8]);
    /// match client.edge_contact(&panda, &q0, &q1, 0.01, 1e-6)? {
    ///     None => println!("the whole edge is clear"),
    ///     Some(c) => println!("{} touches {} in s ∈ [{}, {}]", c.a, c.b, c.s_lo, c.s_hi),
    /// }
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// [`SceneError::EdgeEnds`] when `from` and `to` are not one position
    /// per joint; as [`SceneQuery::into_contacts`] otherwise
    /// ([`SceneError::OutOfLimits`], [`SceneError::NonFinitePose`],
    /// [`SceneError::Malformed`] for `from == to`).
    #[cfg(feature = "robots")]
    pub fn edge_contact(
        &mut self,
        robot: &RobotHandle,
        from: &[f64],
        to: &[f64],
        margin: f64,
        bracket: f64,
    ) -> Result<Option<Contact>, SceneError> {
        let joints = robot.positions.len();
        if from.len() != joints || to.len() != joints {
            return Err(SceneError::EdgeEnds);
        }
        let both: Vec<f64> = from.iter().chain(to).copied().collect();
        let mut contact = [Contact::default()];
        let summary = self
            .within(robot, margin)
            .continuous(Steps::joints(robot, &both), bracket)
            .into_contacts(&mut contact)?;
        Ok((summary.written > 0).then_some(contact[0]))
    }
}
