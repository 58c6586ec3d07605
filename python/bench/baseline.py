"""The baseline checker, written as Python planning code writes it today
(pyroboplan's way): pinocchio's geometry model from the URDF (meshes as
coal's BVH triangle models), the SRDF's pairs removed, the scene's boxes and
cylinders added as coal shapes, and one ``pinocchio.computeCollisions`` per
state, with coal's security margin as the margin."""

from __future__ import annotations

from typing import Sequence

import coal
import numpy as np
import pinocchio as pin
from scenes import PACKAGES, PANDA_SRDF, Obstacle, panda_urdf


def coal_shape(o: Obstacle) -> coal.CollisionGeometry:
    if o.kind == "box":
        return coal.Box(*(2.0 * np.asarray(o.size["half_extents"])))
    if o.kind == "cylinder":
        return coal.Cylinder(o.size["radius"], o.size["length"])
    if o.kind == "sphere":
        return coal.Sphere(o.size["radius"])
    raise ValueError(f"{o.name}: no coal shape for {o.kind!r}")


class PinCoal:
    """The Panda against ``obstacles``: ``is_valid(q)`` for the seven arm
    joints, the fingers held at ``fingers``; ``margin`` is coal's security
    margin (a pair closer than it collides)."""

    def __init__(self, obstacles: Sequence[Obstacle], margin: float, fingers: float) -> None:
        urdf = panda_urdf(fingers)
        self.model = pin.buildModelFromXML(urdf)
        geom = pin.buildGeomFromUrdfString(
            self.model, urdf, pin.COLLISION, package_dirs=[str(PACKAGES)]
        )
        geom.addAllCollisionPairs()
        pin.removeCollisionPairs(self.model, geom, str(PANDA_SRDF))
        links = len(geom.geometryObjects)
        for o in obstacles:
            placement = pin.SE3(pin.Quaternion(*o.quaternion[[3, 0, 1, 2]]).matrix(), o.translation)
            geom.addGeometryObject(pin.GeometryObject(o.name, 0, 0, placement, coal_shape(o)))
        for i in range(links):
            for j in range(links, len(geom.geometryObjects)):
                geom.addCollisionPair(pin.CollisionPair(i, j))
        self.geom = geom
        self.data = self.model.createData()
        self.gdata = pin.GeometryData(geom)
        for request in self.gdata.collisionRequests:
            request.security_margin = margin
        self.q = pin.neutral(self.model)
        self.q[7:] = fingers
        self.checks = 0

    def is_valid(self, q: Sequence[float]) -> bool:
        """Whether no pair collides (within the margin) at ``q``."""
        self.checks += 1
        self.q[:7] = q
        return not pin.computeCollisions(self.model, self.data, self.geom, self.gdata, self.q, True)

    def first_collision(self, q: Sequence[float]) -> str:
        """The names of the first colliding pair at ``q`` (``""`` if none)."""
        self.q[:7] = q
        pin.computeCollisions(self.model, self.data, self.geom, self.gdata, self.q, False)
        for k, r in enumerate(self.gdata.collisionResults):
            if r.isCollision():
                p = self.geom.collisionPairs[k]
                g = self.geom.geometryObjects
                return f"{g[p.first].name}-{g[p.second].name}"
        return ""

    def clearance(self, q: Sequence[float]) -> float:
        """The least distance over every checked pair at ``q`` (coal's
        distance: negative where shapes overlap), as a clearance objective
        asks for it."""
        self.checks += 1
        self.q[:7] = q
        k = pin.computeDistances(self.model, self.data, self.geom, self.gdata, self.q)
        return float(self.gdata.distanceResults[k].min_distance)
