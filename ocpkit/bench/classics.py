"""`ocpkit bench classics`: the classic optimal control problems (ocpkit.problems) × transcription × grid × solver,
each solution against its published optimum and certified by re-integration (ocpkit.ocp.certify); with
`peers=("rockit",)` the same problems with rockit's multiple shooting and direct collocation, certified the same
way, in the same table.

Columns: problem, method (ocpkit's transcription or rockit's method), grid (knots per segment, or rockit's
intervals), segments, solver,
status, objective, optimum, error (|J − J*| / |J*|), re-integration error and excess (the certificate's, relative),
certified, iterations, time (s: building the NLP and solving it; for rockit its `solve`, which does both). With more
than one grid, one convergence picture per problem: error against grid per method.
"""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from tqdm import tqdm  # noqa: E402

from ocpkit.bench.common import machine  # noqa: E402
from ocpkit.errors import OptionError  # noqa: E402
from ocpkit.ocp import solve  # noqa: E402
from ocpkit.ocp.certify import certify, certify_peer  # noqa: E402
from ocpkit.ocp.mesh import adapt  # noqa: E402
from ocpkit.ocp.rockit_peer import METHODS, solve_with_rockit  # noqa: E402
from ocpkit.problems import CLASSICS, Classic, classic  # noqa: E402
from ocpkit.transcription import TRANSCRIPTIONS  # noqa: E402
from ocpkit.transcription.pseudospectral import Pseudospectral  # noqa: E402

GRIDS = {"chebyshev": 40, "lgl": 40, "lgr": 40, "trapezoidal": 200, "hermite-simpson": 100}
"""Each transcription's default grid (knots), a pseudospectral one ≥ 30 nodes; on one segment, except:"""
SMOOTH_GRID = (32, 2)
"""A pseudospectral transcription's default (knots, segments) on a smooth problem: 65 nodes."""
REFINE_KNOTS = 10
"""On a non-smooth problem a pseudospectral solve at its GRIDS knots is refined once (`ocpkit.ocp.mesh.adapt`):
segments of this many knots that end at the control's switches; iterations and time are both solves'."""
PEER_INTERVALS = 100
"""rockit's control intervals by default."""
PEERS = ("rockit",)


@dataclass(frozen=True)
class Row:
    """One solve of one classic problem (module docstring for the columns)."""

    problem: str
    method: str
    grid: int
    segments: int
    solver: str
    status: str
    objective: float
    optimum: float
    error: float
    reintegration: float
    excess: float
    certified: bool
    iterations: int
    time: float


def run_classics(out: Path, problems: tuple[str, ...] = (), transcriptions: tuple[str, ...] = (),
                 grids: tuple[int, ...] = (), solvers: tuple[str, ...] = ("ipopt",),
                 peers: tuple[str, ...] = ()) -> list[Row]:
    """Every problem × transcription × grid × solver (the defaults: all problems, all transcriptions at their
    GRIDS, a pseudospectral one at SMOOTH_GRID on a smooth problem and refined on another, ipopt; given `grids`,
    each on one segment) and, per peer, each of its methods at PEER_INTERVALS (or `grids`); the table printed,
    written to out/classics.csv, and the convergence pictures when there are several grids."""
    unknown = sorted(set(peers) - set(PEERS))
    if unknown:
        raise OptionError(f"--peers: unknown peer(s) {', '.join(unknown)}; known: {', '.join(PEERS)}")
    chosen = [classic(name) for name in problems] or list(CLASSICS.values())
    methods = transcriptions or tuple(GRIDS)
    jobs = [(c, m, n, s, not grids) for c in chosen for m in methods for n in (grids or (GRIDS.get(m, 40),))
            for s in solvers]
    jobs += [(c, f"rockit {m}", n, "ipopt", False) for c in chosen for _ in peers for m in METHODS
             for n in (grids or (PEER_INTERVALS,))]
    rows = [_solve(*job) for job in tqdm(jobs, desc="classics", unit="solve")]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "classics.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(Row.__dataclass_fields__))
        writer.writeheader()
        writer.writerows(asdict(row) for row in rows)
    print(table(rows))
    print(machine())
    if len(grids) > 1:
        for c in chosen:
            _convergence_picture([r for r in rows if r.problem == c.name], c, out / f"convergence-{c.name}.png")
    print(f"written to {out.resolve()}")
    return rows


def _solve(problem: Classic, method: str, grid: int, solver: str, default: bool) -> Row:
    """One row: ocpkit's `method` (a transcription; at the `default` grid, SMOOTH_GRID or a refinement for a
    pseudospectral one) or "rockit <method>"."""
    model = problem.build()
    segments = 1
    if method.startswith("rockit "):
        peer = solve_with_rockit(model, method.split(" ", 1)[1], grid)
        certificate = certify_peer(model, peer)
        status = "converged" if peer.success else peer.status
        objective, iterations, elapsed = peer.objective, peer.iterations, peer.wall_time
    else:
        pseudospectral = default and issubclass(TRANSCRIPTIONS.get(method), Pseudospectral)
        if pseudospectral and problem.smooth:
            grid, segments = SMOOTH_GRID
        if pseudospectral and not problem.smooth:
            solves = adapt(model, method, grid, REFINE_KNOTS, solver=solver)
        else:
            solves = [solve(model, method, grid, solver, {"segments": segments} if segments > 1 else {})]
        solution = solves[-1]
        grid, segments = solution.knots, solution.segments
        iterations = sum(s.iterations for s in solves)
        elapsed = sum(s.setup_time + s.wall_time for s in solves)
        certificate = certify(solution)
        status, objective = solution.status, solution.objective
    error = abs(objective - problem.optimum) / abs(problem.optimum)
    return Row(problem.name, method, grid, segments, solver, status, objective, problem.optimum, error,
               certificate.state_error, certificate.excess, certificate.passed, iterations, elapsed)


def table(rows: list[Row]) -> str:
    """The rows as a fixed-width table."""
    header = (f"{'problem':18s} {'method':29s} {'grid':>6s} {'solver':9s} {'status':15s} {'objective':>14s} "
              f"{'error':>8s} {'re-int':>8s} {'excess':>8s} {'cert':>4s} {'iters':>5s} {'time s':>7s}")
    lines = [header, "-" * len(header)]
    for r in rows:
        grid = f"{r.grid}" if r.segments == 1 else f"{r.grid}×{r.segments}"
        lines.append(f"{r.problem:18s} {r.method:29s} {grid:>6s} {r.solver:9s} {r.status:15s} {r.objective:14.8g} "
                     f"{r.error:8.1e} {r.reintegration:8.1e} {r.excess:8.1e} {'yes' if r.certified else 'no':>4s} "
                     f"{r.iterations:5d} {r.time:7.2f}")
    return "\n".join(lines)


def _convergence_picture(rows: list[Row], problem: Classic, path: Path) -> None:
    """Relative objective error against grid, one line per method and solver (log-log)."""
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    for key in sorted({(r.method, r.solver) for r in rows}):
        mine = sorted((r for r in rows if (r.method, r.solver) == key), key=lambda r: r.grid)
        axes.loglog([r.grid for r in mine], [max(r.error, 1e-16) for r in mine], "o-", label=" / ".join(key))
    axes.set(xlabel="grid (knots or intervals)", ylabel="|J − J*| / |J*|",
             title=f"{problem.name} ({'smooth' if problem.smooth else 'non-smooth'} optimum)")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
