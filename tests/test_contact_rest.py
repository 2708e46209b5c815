"""Contact search: the broad phase against all pairs, threaded against serial narrow phase. The
penetrations F / k of a resting rod and of the tip, with their force and energy balances, are rows
of the verification table (tests/test_verification_table.py)."""

import numpy as np
import pytest

from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, WALL_T
from colonsim.insertion.study.verification_contact import rod_on_sheet

E, RHO, D, T = SCOPE_E, SCOPE_RHO, SCOPE_D, WALL_T


def test_broad_phase_finds_every_contact_of_all_pairs():
    # A bent rod pressed into a tube wall: the cell-hash candidates must give exactly the
    # contact forces of a brute-force search over all (node, segment) pairs.
    nodes, tri, _ = straight_tube(0.15, 0.036, 4e-3)
    wall = Shell(nodes, tri, T, load_material(REFERENCE_MATERIAL_PATH), name="wall")
    s = np.linspace(0.0, 0.12, 41)
    centre = np.column_stack((0.01 + s, 0.011 * np.sin(30 * s), 0.011 * np.cos(20 * s)))
    rod = Rod(centre, D, E, RHO)
    contact = RodShellContact(rod, wall, friction=0.2)
    state = {"scope": _State(rod), "wall": _State(wall)}
    rng = np.random.default_rng(1)
    state["scope"].v[:] = rng.normal(size=state["scope"].v.shape) * 0.01
    contact.compute(state, 1e-6)
    assert contact.n_active > 20
    assert contact.n_candidates < 0.05 * len(nodes) * len(rod.segments)
    # brute force: every wall node against every segment
    xs, xr = state["wall"].x, state["scope"].x
    a, b = xr[:-1], xr[1:]
    e = b - a
    w = xs[:, None, :] - a[None]
    t = np.clip(np.einsum("nsk,sk->ns", w, e) / np.einsum("sk,sk->s", e, e), 0.0, 1.0)
    dist = np.linalg.norm(w - t[..., None] * e[None], axis=2)
    in_contact = dist.min(axis=1) < rod.radius + 0.5 * T
    near = np.flatnonzero(dist.min(axis=1) < contact.cutoff)
    assert np.array_equal(np.sort(contact._points), near)
    assert contact.n_candidates == int((dist < contact.cutoff).sum())
    got = np.linalg.norm(state["wall"].f_con, axis=1) > 0.0
    assert np.array_equal(got, in_contact)
    # action = reaction
    assert np.allclose(state["wall"].f_con.sum(axis=0), -state["scope"].f_con.sum(axis=0), atol=1e-12)


class _State:
    def __init__(self, body):
        self.x = body.x0.copy()
        self.v = np.zeros_like(self.x)
        self.f_con = np.zeros_like(self.x)
        self.fixed = np.zeros(len(self.x), dtype=np.uint8)


def test_threaded_narrow_phase_matches_serial(two_threads):
    # Large contact sets run the narrow phase on threads; it must give the serial result
    # (same arithmetic per candidate, only the order of the scalar sums differs: 1e-12).
    if not two_threads:
        return  # checked on two threads in a child process (the fixture)
    wall, rod, contact, under = rod_on_sheet(friction=0.2)
    xr = rod.x0.copy()
    xr[:, 2] -= 1e-4  # press the rod into the wall
    out = []
    for threshold in (10**9, 0):
        contact.parallel_min_candidates = threshold
        state = {"scope": _State(rod), "wall": _State(wall)}
        state["scope"].x[:] = xr
        state["scope"].v[:, 0] = 0.01
        contact.compute(state, 1e-6)
        out.append((state["wall"].f_con.copy(), state["scope"].f_con.copy(), contact.energy))
    assert np.allclose(out[0][0], out[1][0], rtol=0, atol=1e-12)
    assert np.allclose(out[0][1], out[1][1], rtol=0, atol=1e-12)
    assert out[0][2] == pytest.approx(out[1][2], rel=1e-12)

