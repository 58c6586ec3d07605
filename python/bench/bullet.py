"""A reference checker, written as pybullet planning code writes it
(pybullet_planning's way): the URDF loaded with a fixed base, the scene's
boxes, cylinders and spheres as static bodies, and a state valid when
``getClosestPoints`` finds no pair within the margin: the robot against each
obstacle body, and each pair of its links the SRDF does not disable.
pybullet collides a mesh through its convex hull, so it answers for a fatter
robot than the URDF's meshes: a reference point for speed, not a truth."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from typing import Sequence

import numpy as np
import pybullet as pb
from scenes import PACKAGES, PANDA_SRDF, Obstacle, panda_urdf


def _shape(client: int, o: Obstacle) -> int:
    if o.kind == "box":
        return pb.createCollisionShape(
            pb.GEOM_BOX, halfExtents=list(o.size["half_extents"]), physicsClientId=client
        )
    if o.kind == "cylinder":
        return pb.createCollisionShape(
            pb.GEOM_CYLINDER,
            radius=o.size["radius"],
            height=o.size["length"],
            physicsClientId=client,
        )
    if o.kind == "sphere":
        return pb.createCollisionShape(
            pb.GEOM_SPHERE, radius=o.size["radius"], physicsClientId=client
        )
    raise ValueError(f"{o.name}: no pybullet shape for {o.kind!r}")


class Bullet:
    """The Panda against ``obstacles`` in a headless pybullet world:
    ``is_valid(q)`` for the seven arm joints, the fingers held at
    ``fingers``; a pair closer than ``margin`` collides."""

    def __init__(self, obstacles: Sequence[Obstacle], margin: float, fingers: float) -> None:
        import tempfile

        self.client = pb.connect(pb.DIRECT)
        # pybullet does not resolve package:// URLs: the URDF gets the
        # meshes' file paths; the visual meshes are not vendored, and a
        # checker does not need them.
        urdf = re.sub(r"<visual>.*?</visual>", "", panda_urdf(fingers), flags=re.S)
        urdf = urdf.replace("package://", f"{PACKAGES}/")
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
            f.write(urdf)
            path = f.name
        self.robot = pb.loadURDF(path, useFixedBase=True, physicsClientId=self.client)
        names = {}
        movable = []
        for j in range(pb.getNumJoints(self.robot, physicsClientId=self.client)):
            info = pb.getJointInfo(self.robot, j, physicsClientId=self.client)
            names[info[12].decode()] = j
            if info[2] != pb.JOINT_FIXED:
                movable.append((j, info[1].decode()))
        self.arm = [j for j, name in movable if "finger" not in name][:7]
        for j, name in movable:
            if "finger" in name:
                pb.resetJointState(self.robot, j, fingers, physicsClientId=self.client)
        # The base link is -1 in pybullet.
        base = pb.getBodyInfo(self.robot, physicsClientId=self.client)[0].decode()
        names[base] = -1
        disabled = set()
        for d in ET.parse(PANDA_SRDF).getroot().iter("disable_collisions"):
            disabled.add(frozenset((d.get("link1"), d.get("link2"))))
        links = sorted(names.items(), key=lambda kv: kv[1])
        self.self_pairs = [
            (a, b)
            for i, (na, a) in enumerate(links)
            for nb, b in links[i + 1 :]
            if frozenset((na, nb)) not in disabled
            and pb.getCollisionShapeData(self.robot, a, physicsClientId=self.client)
            and pb.getCollisionShapeData(self.robot, b, physicsClientId=self.client)
        ]
        self.obstacles = [
            pb.createMultiBody(
                baseMass=0.0,
                baseCollisionShapeIndex=_shape(self.client, o),
                basePosition=o.translation.tolist(),
                baseOrientation=o.quaternion.tolist(),
                physicsClientId=self.client,
            )
            for o in obstacles
        ]
        self.margin = margin
        self.checks = 0

    def is_valid(self, q: Sequence[float]) -> bool:
        """Whether no pair is within the margin at ``q``."""
        self.checks += 1
        c = self.client
        for j, x in zip(self.arm, np.asarray(q, dtype=float)):
            pb.resetJointState(self.robot, j, float(x), physicsClientId=c)
        for body in self.obstacles:
            if pb.getClosestPoints(self.robot, body, self.margin, physicsClientId=c):
                return False
        for a, b in self.self_pairs:
            if pb.getClosestPoints(self.robot, self.robot, self.margin, a, b, physicsClientId=c):
                return False
        return True

    def clearance(self, q: Sequence[float], reach: float = 10.0) -> float:
        """The least distance over every checked pair at ``q`` (negative where
        shapes overlap; ``reach`` where nothing is nearer), as a clearance
        objective asks for it."""
        self.checks += 1
        c = self.client
        for j, x in zip(self.arm, np.asarray(q, dtype=float)):
            pb.resetJointState(self.robot, j, float(x), physicsClientId=c)
        least = reach
        for body in self.obstacles:
            for point in pb.getClosestPoints(self.robot, body, reach, physicsClientId=c):
                least = min(least, point[8])
        for a, b in self.self_pairs:
            for point in pb.getClosestPoints(
                self.robot, self.robot, reach, a, b, physicsClientId=c
            ):
                least = min(least, point[8])
        return float(least)

    def close(self) -> None:
        """Disconnects the pybullet world."""
        pb.disconnect(self.client)
