//! Registering, finding and removing objects, and the server's counters:
//! the admin requests of a [`Client`].

use std::time::Instant;

use gjkd_proto::{AdminChunk, AdminOp, AdminReply, AdminRequest, Vertex};
use nalgebra::{Isometry3, Point3, Vector3};

use crate::connection::RETRY_PAUSE;
use crate::{
    Client, ClientError, Geometry, LookupError, ObjectId, Piece, Pose, RegisterError, RemoveError,
    ServerStats, StatsError, op_error,
};
#[cfg(doc)]
use crate::{ConnectError, ErrorCode, MAX_NAME_LEN, MAX_PIECES};

impl Client {
    /// Registers an object at the identity pose, without a name.
    ///
    /// # Errors
    /// - [`RegisterError::InvalidShape`], before anything is sent: a
    ///   negative half extent, a compound inside a compound, more than
    ///   [`MAX_PIECES`] pieces, more than `u32::MAX` vertices.
    /// - A refusal by the server, and nothing is stored:
    ///   [`RegisterError::EmptyVertices`], [`RegisterError::InvalidRadius`]
    ///   (negative, NaN, infinite, or above 2^999, about 5e300),
    ///   [`RegisterError::NonFiniteVertex`] (NaN, infinite, or the shape,
    ///   its vertices plus its radius, reaching beyond 2^999 from its body
    ///   origin), [`RegisterError::TooManyVertices`] (over the server's
    ///   `--max-vertices`), [`RegisterError::EmptyCompound`],
    ///   [`RegisterError::TooManyPieces`], [`RegisterError::NonFinitePose`]
    ///   or [`RegisterError::BadQuaternion`] (a piece offset),
    ///   [`RegisterError::TooManyObjects`] (the server's `--max-objects`),
    ///   [`RegisterError::StorageFull`] (the server's disk has no room to
    ///   store the object; the same call succeeds once there is room),
    ///   [`RegisterError::Internal`] (the store failed otherwise). Each
    ///   has its [`ErrorCode`] ([`RegisterError::code`]).
    /// - [`RegisterError::Connection`] with [`ConnectError::ServerGone`] or
    ///   [`ConnectError::Timeout`](crate::ConnectError::Timeout), after
    ///   the retries below. **The registration may then have happened**:
    ///   the request may have reached the server and been stored before
    ///   the server died or the answer came too late, and no retry reached
    ///   a server within the timeout. An object registered under a name can be
    ///   found again with [`Client::lookup`]; an unnamed one cannot be named
    ///   by anyone, so register what must not be orphaned with a name.
    ///
    /// # Retries
    /// Each registration carries a random token. When the server turns out
    /// to be gone (it died, or was restarted), this call reconnects and
    /// sends the same registration again, with the same token, until its
    /// timeout has passed: a server that stored the object before it died
    /// answers the retry with that object's id (it keeps the tokens of each
    /// client's last 64 registrations with the objects, across restarts),
    /// so a retry never stores a second object. So a server restarted
    /// within the timeout costs no orphan. A timeout from
    /// a server that is alive is not retried (the deadline has passed). No
    /// other call retries by itself: a pose update or query that failed is
    /// simply sent again by the caller, and [`Client::remove`] retried
    /// after a lost reply answers [`ErrorCode::UnknownObject`] if the first
    /// attempt removed the object.
    pub fn register(&mut self, geometry: &Geometry<'_>) -> Result<ObjectId, RegisterError> {
        self.register_with(geometry, None, &Isometry3::identity())
    }

    /// Registers an object with a unique `name` (so that other clients can
    /// [`lookup`](Client::lookup) it) and an initial pose.
    ///
    /// # Errors
    /// As [`Client::register`], plus [`RegisterError::NameTaken`] and
    /// [`RegisterError::NameTooLong`] for a name over [`MAX_NAME_LEN`]
    /// bytes.
    pub fn register_named(
        &mut self,
        name: &str,
        geometry: &Geometry<'_>,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, RegisterError> {
        self.register_with(geometry, Some(name), pose)
    }

    fn register_with(
        &mut self,
        geometry: &Geometry<'_>,
        name: Option<&str>,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, RegisterError> {
        let mut request = AdminRequest::new(AdminOp::Register);
        request.pose = Pose::from_isometry(pose);
        if let Some(name) = name
            && !request.set_name(name)
        {
            return Err(RegisterError::NameTooLong);
        }
        request.token = self.tokens.next();
        let mut vertices = std::mem::take(&mut self.vertex_scratch);
        vertices.clear();
        let built = Self::encode(geometry, &mut request, &mut vertices);
        let result = built.and_then(|()| {
            self.register_retrying(&request, &vertices)
                .map_err(op_error)
        });
        self.vertex_scratch = vertices;
        let id = result.map(|r| ObjectId::from_raw(r.id))?;
        self.ending.object(id);
        Ok(id)
    }

    /// Sends a registration and, while the server is gone, sends it again
    /// with the same token (reconnecting) until the call's deadline: the
    /// server answers a repeated token with the object it stored, so this
    /// never registers twice.
    fn register_retrying(
        &mut self,
        request: &AdminRequest,
        vertices: &[Vertex],
    ) -> Result<AdminReply, ClientError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            match self.admin_until(request, AdminChunk::from_vertices(vertices), deadline) {
                Err(ClientError::ServerGone(_)) if Instant::now() + RETRY_PAUSE < deadline => {
                    std::thread::sleep(RETRY_PAUSE);
                }
                outcome => return outcome,
            }
        }
    }

    /// The wire form of `geometry` into `request` and `vertices`.
    fn encode(
        geometry: &Geometry<'_>,
        request: &mut AdminRequest,
        vertices: &mut Vec<Vertex>,
    ) -> Result<(), RegisterError> {
        geometry
            .encode(request, vertices)
            .map_err(RegisterError::InvalidShape)
    }

    /// Registers a ball of `radius` about the body origin.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_sphere(&mut self, radius: f64) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Sphere { radius })
    }

    /// Registers the segment `a`–`b` grown by `radius`.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_capsule(
        &mut self,
        a: Point3<f64>,
        b: Point3<f64>,
        radius: f64,
    ) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Capsule { a, b, radius })
    }

    /// Registers a box with these half extents, centred on the body origin,
    /// its edges rounded by `radius` (0 for a sharp box).
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_cuboid(
        &mut self,
        half_extents: Vector3<f64>,
        radius: f64,
    ) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Cuboid {
            half_extents,
            radius,
        })
    }

    /// Registers an exact cylinder about the body z axis, centred on the
    /// body origin, of `radius` and `half_height` (half its length), its
    /// edges rounded by `rounding` (0 for sharp rims): see
    /// [`Geometry::Cylinder`]. For a name and an initial pose, pass that
    /// geometry to [`Client::register_named`]; a compound takes cylinder
    /// pieces too.
    ///
    /// ```no_run
    /// use gjkd_client::{Client, Geometry, QueryOptions};
    /// use nalgebra::Isometry3;
    ///
    /// # fn main() -> Result<(), gjkd_client::ClientError> {
    /// let mut client = Client::connect("gjkd")?;
    /// let can = client.register_cylinder(0.5, 1.0, 0.0)?;
    /// let ball = client.register_named(
    ///     "ball", &Geometry::Sphere { radius: 0.25 }, &Isometry3::translation(2.0, 0.0, 0.3))?;
    /// // Beside the curved face: 2 - 0.5 - 0.25.
    /// let d = client.distance(can, ball, &QueryOptions::default())?.distance;
    /// assert!((d - 1.25).abs() < 1e-12);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`Client::register`]: [`RegisterError::InvalidRadius`] for a
    /// negative, NaN or infinite radius, half-height or rounding (or a
    /// cylinder reaching beyond 2^999).
    pub fn register_cylinder(
        &mut self,
        radius: f64,
        half_height: f64,
        rounding: f64,
    ) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Cylinder {
            radius,
            half_height,
            rounding,
        })
    }

    /// Registers the convex hull of `vertices` grown by `radius`.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_polytope(
        &mut self,
        vertices: &[Point3<f64>],
        radius: f64,
    ) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Polytope { vertices, radius })
    }

    /// Registers a union of convex pieces.
    ///
    /// ```no_run
    /// use gjkd_client::{Client, Geometry, Piece};
    /// use nalgebra::{Isometry3, Point3};
    ///
    /// # fn main() -> Result<(), gjkd_client::ClientError> {
    /// let mut client = Client::connect("gjkd")?;
    /// let ball = Geometry::Sphere { radius: 0.3 };
    /// let bar = Geometry::Capsule {
    ///     a: Point3::new(-1.0, 0.0, 0.0),
    ///     b: Point3::new(1.0, 0.0, 0.0),
    ///     radius: 0.05,
    /// };
    /// let dumbbell = client.register_compound(&[
    ///     Piece { offset: Isometry3::translation(-1.0, 0.0, 0.0), geometry: ball },
    ///     Piece { offset: Isometry3::identity(), geometry: bar },
    ///     Piece { offset: Isometry3::translation(1.0, 0.0, 0.0), geometry: ball },
    /// ])?;
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`Client::register`], plus [`RegisterError::EmptyCompound`] and
    /// [`RegisterError::InvalidShape`] for a nested compound or more than
    /// [`MAX_PIECES`] pieces.
    pub fn register_compound(&mut self, pieces: &[Piece<'_>]) -> Result<ObjectId, RegisterError> {
        self.register(&Geometry::Compound(pieces))
    }

    /// Removes an object this client registered. Its id is never reused.
    ///
    /// # Errors
    /// [`RemoveError::UnknownObject`], [`RemoveError::NotOwner`] for
    /// another client's object, [`RemoveError::ReadOnly`] for a scene
    /// object, [`RemoveError::StorageFull`] when the server's disk has no
    /// room to store the removal (the object stays; the same call succeeds
    /// once there is room); the connection faults.
    pub fn remove(&mut self, id: ObjectId) -> Result<(), RemoveError> {
        let mut request = AdminRequest::new(AdminOp::Remove);
        request.object = id.raw();
        self.admin(&request, &[]).map_err(op_error::<RemoveError>)?;
        self.ending.removed(id);
        Ok(())
    }

    /// The id of the object named `name` (scene objects, or objects
    /// registered with [`Client::register_named`]).
    ///
    /// # Errors
    /// [`LookupError::UnknownName`], [`LookupError::NameTooLong`] for a
    /// name over [`MAX_NAME_LEN`] bytes; the connection faults.
    pub fn lookup(&mut self, name: &str) -> Result<ObjectId, LookupError> {
        let mut request = AdminRequest::new(AdminOp::Lookup);
        if !request.set_name(name) {
            return Err(LookupError::NameTooLong);
        }
        self.admin(&request, &[])
            .map(|r| ObjectId::from_raw(r.id))
            .map_err(op_error)
    }

    /// The server's counters: objects, requests, warm-start cache use.
    ///
    /// # Errors
    /// The connection faults of every call ([`StatsError`]).
    pub fn stats(&mut self) -> Result<ServerStats, StatsError> {
        self.admin(&AdminRequest::new(AdminOp::Stats), &[])
            .map(|r| r.stats)
            .map_err(op_error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gjkd_proto::{piece_kind, shape_kind};

    /// Vertices, radius and piece kind of a convex geometry's wire form.
    fn push_convex(g: &Geometry<'_>, v: &mut Vec<Vertex>) -> Result<(f64, u32), RegisterError> {
        let mut req = AdminRequest::new(AdminOp::Register);
        Client::encode(g, &mut req, v)?;
        Ok((req.pieces[0].rounding, req.pieces[0].kind))
    }

    #[test]
    fn a_negative_half_extent_is_refused_before_sending() {
        for h in [
            Vector3::new(-1.0, 1.0, 1.0),
            Vector3::new(1.0, -0.0001, 1.0),
            Vector3::new(1.0, 1.0, -f64::MIN_POSITIVE),
        ] {
            let mut v = Vec::new();
            let g = Geometry::Cuboid {
                half_extents: h,
                radius: 0.0,
            };
            assert_eq!(
                push_convex(&g, &mut v),
                Err(RegisterError::InvalidShape(
                    gjkd_proto::ShapeError::HalfExtentIsNegative
                )),
                "{h:?}"
            );
            assert!(v.is_empty(), "nothing encoded for {h:?}");
        }
        // Zero (a flat box) and -0.0 are documented as valid.
        let mut v = Vec::new();
        let flat = Geometry::Cuboid {
            half_extents: Vector3::new(1.0, 0.0, -0.0),
            radius: 0.0,
        };
        assert_eq!(push_convex(&flat, &mut v), Ok((0.0, piece_kind::HULL)));
    }

    #[test]
    fn cuboid_vertices_follow_gjk_order() {
        let mut v = Vec::new();
        let g = Geometry::Cuboid {
            half_extents: Vector3::new(1.0, 2.0, 3.0),
            radius: 0.0,
        };
        assert_eq!(push_convex(&g, &mut v), Ok((0.0, piece_kind::HULL)));
        assert_eq!(v.len(), 8);
        assert_eq!(
            v[0],
            Vertex {
                x: -1.0,
                y: -2.0,
                z: -3.0
            }
        );
        assert_eq!(
            v[5],
            Vertex {
                x: 1.0,
                y: -2.0,
                z: 3.0
            }
        );
    }

    #[test]
    fn compounds_encode_their_piece_table() {
        let pts = [Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
        let pieces = [
            Piece {
                offset: Isometry3::translation(1.0, 0.0, 0.0),
                geometry: Geometry::Sphere { radius: 0.5 },
            },
            Piece {
                offset: Isometry3::identity(),
                geometry: Geometry::Polytope {
                    vertices: &pts,
                    radius: 0.1,
                },
            },
        ];
        let mut req = AdminRequest::new(AdminOp::Register);
        let mut v = Vec::new();
        Client::encode(&Geometry::Compound(&pieces), &mut req, &mut v).expect("valid");
        assert_eq!(req.shape, shape_kind::COMPOUND);
        assert_eq!(req.piece_count, 2);
        assert_eq!(req.pieces[0].vertex_count, 1);
        assert_eq!(req.pieces[1].vertex_count, 2);
        assert_eq!(req.pieces[1].rounding, 0.1);
        assert_eq!(req.pieces[0].offset.translation, [1.0, 0.0, 0.0]);
        assert_eq!(v.len(), 3);

        let nested = [Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Compound(&pieces),
        }];
        assert!(matches!(
            Client::encode(&Geometry::Compound(&nested), &mut req, &mut v),
            Err(RegisterError::InvalidShape(
                gjkd_proto::ShapeError::CompoundIsNested
            ))
        ));
    }

    #[test]
    fn cylinders_travel_with_named_dimensions() {
        let can = Geometry::Cylinder {
            radius: 0.5,
            half_height: 2.0,
            rounding: 0.125,
        };
        let mut req = AdminRequest::new(AdminOp::Register);
        let mut v = Vec::new();
        Client::encode(&can, &mut req, &mut v).expect("valid");
        assert_eq!((req.shape, req.piece_count), (shape_kind::CONVEX, 1));
        let desc = req.pieces[0];
        assert_eq!((desc.kind, desc.vertex_count), (piece_kind::CYLINDER, 0));
        assert_eq!(desc.rounding, 0.125);
        assert_eq!((desc.cylinder_radius, desc.half_height), (0.5, 2.0));
        assert!(v.is_empty(), "a cylinder sends no vertices");

        let pieces = [
            Piece {
                offset: Isometry3::translation(0.0, 0.0, 1.0),
                geometry: Geometry::Sphere { radius: 0.5 },
            },
            Piece {
                offset: Isometry3::identity(),
                geometry: can,
            },
        ];
        let mut v = Vec::new();
        Client::encode(&Geometry::Compound(&pieces), &mut req, &mut v).expect("valid");
        assert_eq!(req.pieces[0].kind, piece_kind::HULL);
        assert_eq!(req.pieces[1].kind, piece_kind::CYLINDER);
        assert_eq!(v.len(), 1);

        // A gjk cylinder maps back to the same geometry, a polytope to its
        // vertices.
        let c = gjk::Convex::cylinder(0.5, 2.0, 0.125).expect("valid");
        assert_eq!(Geometry::of_convex(&c), can);
        let b = gjk::Convex::sphere(0.3).expect("valid");
        assert!(matches!(
            Geometry::of_convex(&b),
            Geometry::Polytope { vertices, radius } if vertices.len() == 1 && radius == 0.3
        ));
    }
}
