//! The admin service's handler: hello, statistics, registrations,
//! removals, look-ups and robots.

use gjkd_proto::{AdminChunk, AdminOp, AdminReply, AdminRequest, ErrorCode};

use super::decode::decode_registration;
use crate::engine::checks::check_pose;
use crate::engine::objects::Owner;
use crate::engine::robots::NewRobot;
use crate::engine::state::State;

impl State {
    /// Answers one admin request from client `requester` (the id of its
    /// iceoryx2 node, see [`Owner`]), with the request's slice payload
    /// `payload` (a registration's vertices or a robot's text). With persistence on, a registration or removal is
    /// committed to the database ([`crate::persist::database`]) before this returns;
    /// if the commit fails the change is undone and the reply is
    /// [`ErrorCode::Internal`], so an acknowledged change is always on disk.
    pub fn handle_admin(
        &mut self,
        requester: u128,
        request: &AdminRequest,
        payload: &[AdminChunk],
    ) -> AdminReply {
        let op = request.op;
        let mut reply = AdminReply {
            op,
            ..AdminReply::default()
        };
        let op_kind = AdminOp::from_raw(op);
        // Only a registration (vertices) and a robot (text) carry a slice: any other request with a
        // slice is malformed (and would otherwise be silently ignored).
        if !payload.is_empty() && !matches!(op_kind, Some(AdminOp::Register | AdminOp::AttachRobot))
        {
            reply.error = ErrorCode::Malformed as u32;
            return reply;
        }
        let outcome = match op_kind {
            Some(AdminOp::Hello) => {
                reply.info = self.info();
                Ok(0)
            }
            Some(AdminOp::Stats) => {
                reply.stats = self.stats();
                Ok(0)
            }
            Some(AdminOp::Register) => {
                decode_registration(&self.limits, request, AdminChunk::vertices(payload)).and_then(
                    |new| {
                        let max = self.limits.max_objects;
                        self.store
                            .register(new, Owner::Client(requester), max, request.token)
                    },
                )
            }
            Some(AdminOp::Remove) => self
                .remove(request.object, requester)
                .map(|()| request.object),
            Some(AdminOp::Lookup) => match (request.name(), request.lookup) {
                (Some(name), gjkd_proto::lookup_kind::OBJECT) => {
                    self.lookup(name).ok_or(ErrorCode::UnknownName)
                }
                (Some(name), gjkd_proto::lookup_kind::ROBOT) => {
                    self.robots.lookup(name).ok_or(ErrorCode::UnknownName)
                }
                _ => Err(ErrorCode::Malformed),
            },
            Some(AdminOp::AttachRobot) => self.attach_request(requester, request, payload),
            Some(AdminOp::RemoveRobot) => match request.name() {
                Some(name) => self.remove_robot(name, requester),
                None => Err(ErrorCode::Malformed),
            },
            None => Err(ErrorCode::Malformed),
        };
        match outcome {
            Ok(id) => reply.id = id,
            Err(e) => reply.error = e as u32,
        }
        reply
    }

    /// Answers an [`AdminOp::AttachRobot`](gjkd_proto::AdminOp::AttachRobot)
    /// request.
    ///
    /// # Errors
    /// [`ErrorCode::Malformed`] for a missing name or text that does not
    /// unpack, and those of [`attach`].
    fn attach_request(
        &mut self,
        requester: u128,
        request: &AdminRequest,
        text: &[AdminChunk],
    ) -> Result<u64, ErrorCode> {
        let name = request
            .name()
            .filter(|n| !n.is_empty())
            .ok_or(ErrorCode::Malformed)?
            .to_owned();
        let text =
            AdminChunk::text_of(text, u64::from(request.text_len)).ok_or(ErrorCode::Malformed)?;
        let (urdf, srdf) = match text.split_once('\0') {
            Some((urdf, srdf)) => (urdf, Some(srdf)),
            None => (text, None),
        };
        let base = check_pose(&request.pose)?;
        self.attach_robot(NewRobot {
            name: &name,
            urdf,
            srdf,
            base,
            positions: None,
            owner: Owner::Client(requester),
        })
    }
}
