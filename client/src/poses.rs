//! Stored poses read back from the server, a batch of ids at a time.

use std::time::Instant;

use gjkd_proto::{ErrorCode, ObjectId, PosesReply, StoredPose, poses_service_name};
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::request_response;
use nalgebra::Isometry3;

use crate::{Client, ClientError, PoseReadError, Waited, ipc_err, op_error};

type PosesPort = IoxClient<ipc::Service, [u64], (), [StoredPose], PosesReply>;
type PosesService =
    request_response::PortFactory<ipc::Service, [u64], (), [StoredPose], PosesReply>;

/// The pose service's port of one connection, opened at its first use (as
/// the scene service's): clients that never read a pose back never pay
/// for it.
pub(crate) struct PosesPorts {
    // The port before its service, so that it is dropped first.
    port: PosesPort,
    service: PosesService,
}

impl Client {
    /// The stored pose of each of `ids`, in order: what the last
    /// [`Client::set_pose`] (by any client) or registration stored, bit for
    /// bit, and for a robot's link object the pose the server computed from
    /// the robot's last joint positions and base. An id the server does not
    /// hold (never registered, removed, another server run's) gets
    /// `Err(ErrorCode::UnknownObject)` in its entry without failing the
    /// others, as the items of a query batch do. More ids than the server
    /// takes in one request are sent in several. No id at all is an empty
    /// answer, sent nowhere.
    ///
    /// # Errors
    /// [`PoseReadError::Connection`] (a server gone, a timeout and the
    /// other faults of a round trip); [`PoseReadError::BatchTooLarge`] from
    /// a server restarted with a smaller limit since this client split the
    /// ids.
    pub fn poses(
        &mut self,
        ids: &[ObjectId],
    ) -> Result<Vec<Result<Isometry3<f64>, ErrorCode>>, PoseReadError> {
        let mut out = Vec::with_capacity(ids.len());
        if ids.is_empty() {
            return Ok(out);
        }
        let deadline = Instant::now() + self.timeout;
        self.ensure_connected(deadline)
            .map_err(op_error::<PoseReadError>)?;
        let per_request = self.request_limits().map_or(ids.len(), |l| l.items.max(1));
        for chunk in ids.chunks(per_request) {
            self.poses_once(chunk, &mut out)
                .map_err(op_error::<PoseReadError>)?;
        }
        Ok(out)
    }

    /// One request of [`Client::poses`]: at most the server's batch limit.
    fn poses_once(
        &mut self,
        ids: &[ObjectId],
        out: &mut Vec<Result<Isometry3<f64>, ErrorCode>>,
    ) -> Result<(), ClientError> {
        let deadline = Instant::now() + self.timeout;
        self.ensure_connected(deadline)?;
        self.ensure_poses_ports()?;
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let Some(poses) = conn.poses.as_ref() else {
            return Err(self.gone());
        };
        let outcome = (|| {
            if poses.service.dynamic_config().number_of_servers() == 0 {
                return Err(Waited::Gone);
            }
            let loan = poses
                .port
                .loan_slice_uninit(ids.len())
                .map_err(|e| Waited::Failed(ipc_err("poses loan")(e)))?;
            let pending = loan
                .write_from_fn(|i| ids[i].raw())
                .send()
                .map_err(|e| conn.send_failed(&self.node, "poses send", e))?;
            if conn.notify_queries {
                let _ = conn.wake.notify();
            }
            Self::await_reply(&self.node, conn, deadline, self.timeout, || {
                let Some(response) = pending.receive().map_err(ipc_err("poses receive"))? else {
                    return Ok(None);
                };
                crate::reply_accepted(response.user_header().error)?;
                let entries = response.payload();
                if entries.len() != ids.len() {
                    return Err(ClientError::Protocol(format!(
                        "{} poses answer {} ids",
                        entries.len(),
                        ids.len()
                    )));
                }
                Ok(Some(
                    entries
                        .iter()
                        .map(|e| e.pose().map(|p| p.to_isometry_unchecked()))
                        .collect::<Vec<_>>(),
                ))
            })
        })();
        out.extend(self.settle(outcome)?);
        Ok(())
    }

    /// Opens the pose service and its client port on the current
    /// connection, if not yet done.
    fn ensure_poses_ports(&mut self) -> Result<(), ClientError> {
        if self.conn.as_ref().is_none_or(|c| c.poses.is_some()) {
            return Ok(());
        }
        let name = poses_service_name(&self.service);
        let service_name = ServiceName::new(&name).map_err(ipc_err("service name"))?;
        let service = self
            .node
            .service_builder(&service_name)
            .request_response::<[u64], [StoredPose]>()
            .response_user_header::<PosesReply>()
            .open()
            .map_err(|e| self.later_service_failed(&name, "pose", "pose read-back", e))?;
        let port = service
            .client_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(ipc_err("poses client port"))?;
        if let Some(conn) = self.conn.as_mut() {
            conn.poses = Some(PosesPorts { port, service });
        }
        Ok(())
    }
}
