"""``gjkd.local``: distances between shapes held in this process, with no
server. :class:`Local` has the methods of :class:`gjkd.Client` and answers
bit for bit what a server answers for the same inputs."""

from ._native import Local

__all__ = ["Local"]
