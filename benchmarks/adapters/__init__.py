"""Each IK library behind one small interface, so that the protocols treat them alike.

A :class:`Peer` is one library set up for one arm. It offers up to three
:class:`Method`\\ s, one per protocol of :mod:`benchmarks.protocols`:

* ``exact``: the solution for a given redundancy (7-DOF: q7 held at the true value for the
  peers, the true arm angle psi for om_redundant; 6-DOF: the plain solve);
* ``any``: some solution within the limits;
* ``every``: all solutions for a given redundancy value.

A method is split in three so that only the library call is timed: ``prepare`` converts
the target into the library's frames and types, ``call`` is the timed call and
``solutions`` turns its result into joint vectors of the arm.

Peer factories raise :class:`Unavailable` with the reason when a library is missing or
does not handle the arm; the suite prints it and goes on.
"""

# One module per peer (om_peer, analytic: EAIK and ik-geo, urdf_peers: TRAC-IK and ikpy, mink_peers,
# frankik_peer) on base's Peer and Method; PEERS names them in table order.

from __future__ import annotations

from collections.abc import Callable

import numpy as np

import om_redundant as om

from .analytic import Q7_GRID_SIZE, eaik_peer, ik_geo_peer
from .base import (
    BatchMethod,
    Method,
    Peer,
    Unavailable,
    first_within_limits,
    shift_into_limits,
    within_limits,
)
from .frankik_peer import frankik_peer
from .mink_peers import (
    MINK_DAMPING,
    MINK_DT,
    MINK_SOLVER,
    MINK_STEPS,
    mink_example_tasks,
    mink_frame_only_peer,
    mink_peer,
)
from .om_peer import om_redundant_peer
from .urdf_peers import TRAC_IK_EPSILON, TRAC_IK_TIMEOUT, ikpy_peer, trac_ik_peer

#: Peer factories by name, in table order.
PEERS: dict[str, Callable[[om.Arm, np.random.Generator], Peer]] = {
    "om_redundant": om_redundant_peer,
    "EAIK": eaik_peer,
    "ik-geo": ik_geo_peer,
    "frankik": frankik_peer,
    "TRAC-IK": trac_ik_peer,
    "ikpy": ikpy_peer,
    "mink (frame+posture)": mink_peer,
    "mink (frame only)": mink_frame_only_peer,
}

__all__ = [
    "MINK_DAMPING",
    "MINK_DT",
    "MINK_SOLVER",
    "MINK_STEPS",
    "PEERS",
    "Q7_GRID_SIZE",
    "TRAC_IK_EPSILON",
    "TRAC_IK_TIMEOUT",
    "BatchMethod",
    "Method",
    "Peer",
    "Unavailable",
    "eaik_peer",
    "first_within_limits",
    "frankik_peer",
    "ik_geo_peer",
    "ikpy_peer",
    "mink_example_tasks",
    "mink_frame_only_peer",
    "mink_peer",
    "om_redundant_peer",
    "shift_into_limits",
    "trac_ik_peer",
    "within_limits",
]
