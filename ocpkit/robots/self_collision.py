"""Self-collision sphere pairs of an imported robot: non-adjacent links, minus SRDF-disabled pairs, minus pairs
already touching at the zero pose.

Two spheres are a candidate pair when they move relative to each other and their links are not adjacent:
their parent joints (of the planned model, locked joints merged into their parents) differ and neither is
the other's parent. The SRDF's `<disable_collisions link1 link2>` drops link pairs; a pair whose spheres
overlap at the home pose drop their whole link pair (as MoveIt's setup assistant does with links in contact by
default), and are reported. The home pose is the SRDF's first `<group_state>` naming every planned joint (the
Panda's 'ready'), else the zero pose (every planned joint at 0, clipped into its limits).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ocpkit.robots.spheres import Sphere, urdf_root


@dataclass(frozen=True)
class Pairs:
    """Kept pairs (P, 2) of sphere indices, and the link pairs dropped by the SRDF and for touching at `home`."""

    kept: list[tuple[int, int]]
    disabled: set[frozenset[str]]
    touching: set[frozenset[str]]
    home: str


def srdf_disabled(path: Path) -> set[frozenset[str]]:
    """The link pairs of an SRDF's `<disable_collisions>` elements."""
    return {frozenset((e.get("link1"), e.get("link2"))) for e in urdf_root(path).iter("disable_collisions")}


def home_pose(model: pin.Model, srdf: Path | None) -> tuple[np.ndarray, str]:
    """The home configuration (nq,) of the planned `model` (module docstring) and its name."""
    names = list(model.names[1:])
    for state in urdf_root(srdf).iter("group_state") if srdf else []:
        values = {j.get("name"): float(j.get("value")) for j in state.iter("joint")}
        if set(names) <= set(values):
            return np.array([values[n] for n in names]), f"the SRDF's {state.get('name')!r} pose"
    return np.clip(np.zeros(model.nq), model.lowerPositionLimit, model.upperPositionLimit), "the zero pose"


def sphere_world(model: pin.Model, spheres: list[Sphere], qs: np.ndarray) -> np.ndarray:
    """World centres of `spheres` at configurations qs (nq,) or (K, nq): shape (M, 3) or (K, M, 3)."""
    data = model.createData()
    frames = [model.getFrameId(s.link) for s in spheres]
    local = np.array([s.center for s in spheres], dtype=float).reshape(-1, 3)
    out = []
    for q in np.atleast_2d(qs):
        pin.framesForwardKinematics(model, data, q)
        poses = np.array([data.oMf[f].homogeneous for f in frames]).reshape(-1, 4, 4)
        out.append(np.einsum("mij,mj->mi", poses[:, :3, :3], local) + poses[:, :3, 3])
    return out[0] if np.ndim(qs) == 1 else np.array(out)


def self_collision_pairs(model: pin.Model, spheres: list[Sphere], srdf: Path | None) -> Pairs:
    """The self-collision pairs of `spheres` on the planned `model` (module docstring)."""
    joint = [model.frames[model.getFrameId(s.link)].parentJoint for s in spheres]
    disabled = srdf_disabled(srdf) if srdf else set()
    q, home = home_pose(model, srdf)
    centres = sphere_world(model, spheres, q)
    radius = np.array([s.radius for s in spheres])
    candidates, dropped_srdf, touching = [], set(), set()
    for a in range(len(spheres)):
        for b in range(a + 1, len(spheres)):
            ja, jb = joint[a], joint[b]
            if ja == jb or model.parents[ja] == jb or model.parents[jb] == ja:
                continue
            links = frozenset((spheres[a].link, spheres[b].link))
            if links in disabled:
                dropped_srdf.add(links)
                continue
            candidates.append((a, b))
            if np.linalg.norm(centres[a] - centres[b]) < radius[a] + radius[b]:
                touching.add(links)
    kept = [(a, b) for a, b in candidates if frozenset((spheres[a].link, spheres[b].link)) not in touching]
    return Pairs(kept, dropped_srdf, touching, home)

