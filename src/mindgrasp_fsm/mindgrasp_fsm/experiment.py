"""The paper's random-locations experiment, run in-process and in lock-step.

Each trial places one object (random shape, colour, size 0.04-0.06 m, yaw) at a random radius of
0.2-0.7 m and angle of -170..170 deg around the base, resets the arm home, and lets the autonomous
controller search (turning left), centre, approach and grasp it. A trial succeeds when the object
is held above :data:`~mindgrasp_fsm.lockstep.SUCCESS_HEIGHT` after the return to start.
"""

from __future__ import annotations

import logging
import math
import statistics
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.lockstep import LockstepLoop, TrialOutcome
from mindgrasp_fsm.params import SHAPES, FsmParams

log = logging.getLogger(__name__)

COLOURS = ('red', 'yellow', 'blue')


@dataclass(frozen=True)
class TrialSpec:
    """Where one trial's object stands (m, deg) and what it is."""

    index: int
    shape: str
    colour: str
    radius: float
    angle_deg: float
    size: float
    yaw_deg: float

    def scene(self) -> dict:
        """A one-object scene mapping for :meth:`Simulation.load_scene`."""
        return {
            'name': f'random_locations_trial_{self.index}',
            'seed': self.index,
            'defaults': {'density': 600.0, 'friction': 0.9, 'rolling_friction': 0.003,
                         'spinning_friction': 0.001},
            'objects': [{'shape': self.shape, 'colour': self.colour, 'radius': self.radius,
                         'angle_deg': self.angle_deg, 'size': self.size,
                         'yaw_deg': self.yaw_deg}],
        }


def draw_trials(n: int, seed: int, radius: tuple[float, float] = (0.2, 0.7),
                angle_deg: tuple[float, float] = (-170.0, 170.0),
                size: tuple[float, float] = (0.04, 0.06)) -> list[TrialSpec]:
    """``n`` seeded trials; shapes balanced (each shape ``n / 3`` times, shuffled), positions
    uniform over the annulus area."""
    rng = np.random.default_rng(seed)
    shapes = [SHAPES[i % len(SHAPES)] for i in range(n)]
    rng.shuffle(shapes)
    out = []
    for i, shape in enumerate(shapes):
        r = math.sqrt(rng.uniform(radius[0] ** 2, radius[1] ** 2))
        out.append(TrialSpec(
            index=i, shape=shape, colour=str(rng.choice(COLOURS)), radius=float(r),
            angle_deg=float(rng.uniform(*angle_deg)), size=float(rng.uniform(*size)),
            yaw_deg=0.0 if shape == 'sphere' else float(rng.uniform(-45.0, 45.0))))
    return out


@dataclass
class TrialRecord:
    """A trial's placement and outcome (for reports)."""

    index: int
    shape: str
    colour: str
    radius: float
    angle_deg: float
    size: float
    success: bool
    time_to_grasp: float
    duration: float
    attempts: int
    detected_shape: str
    reason: str


def build_loop(params: FsmParams | None = None, shape_model: str | None = None,
               camera_hz: float | None = None, realism: object = None,
               realism_seed: int = 0) -> tuple[LockstepLoop, str]:
    """Simulation + vision pipeline + controller for the experiment; returns (loop, model note).

    ``realism``: a :class:`~mindgrasp_sim.realism.RealismProfile`, its name or a YAML path
    (None: a perfect world); ``realism_seed`` seeds its draws."""
    from mindgrasp_sim.simulation import Simulation
    from mindgrasp_vision.config import VisionConfig

    params = params or FsmParams()
    params.autonomous = True
    cfg = VisionConfig() if shape_model is None else VisionConfig(shape_model=shape_model)
    note = cfg.shape_model
    try:
        classifier = cfg.load_classifier()
    except Exception as exc:
        log.warning('Shape model %s not loaded (%s); the controller uses measured sizes only.',
                    cfg.shape_model, exc)
        classifier, note = None, f'none ({cfg.shape_model} not loaded)'
    if classifier is None and not note.startswith('none'):
        note = 'none'
    sim = Simulation(scene={'name': 'empty', 'objects': [
        {'shape': 'cube', 'colour': 'red', 'radius': 0.5, 'angle_deg': 0}]},
        realism=realism, realism_seed=realism_seed)
    loop = LockstepLoop(sim, cfg.build_pipeline(classifier), GraspFsm.from_params(params),
                        camera_hz=camera_hz)
    return loop, note


def run_random_locations(trials: int, seed: int, params: FsmParams | None = None,
                         timeout: float = 120.0, shape_model: str | None = None,
                         progress: Callable[[TrialRecord], None] | None = None,
                         realism: object = None) -> dict:
    """Run the experiment; returns the summary dict printed by the CLI (see its ``--json``).

    ``realism``: profile, name or YAML path (None: none); its draws are seeded by ``seed``."""
    loop, model_note = build_loop(params, shape_model, realism=realism, realism_seed=seed)
    records: list[TrialRecord] = []
    outcomes: list[TrialOutcome] = []
    wall0 = time.perf_counter()
    sim_time = 0.0
    try:
        for spec in draw_trials(trials, seed):
            loop.sim.load_scene(spec.scene(), seed=spec.index)
            out = loop.run(0, timeout=timeout)
            sim_time += out.duration
            outcomes.append(out)
            rec = TrialRecord(spec.index, spec.shape, spec.colour, spec.radius, spec.angle_deg,
                              spec.size, out.success, out.time_to_grasp, out.duration,
                              out.attempts, out.detected_shape, out.reason)
            records.append(rec)
            if progress is not None:
                progress(rec)
    finally:
        loop.sim.close()
    wall = time.perf_counter() - wall0
    summary = summarise(records, outcomes, seed, wall, sim_time, model_note)
    summary['realism'] = loop.sim.realism.profile.name
    return summary


def summarise(records: list[TrialRecord], outcomes: list[TrialOutcome], seed: int, wall: float,
              sim_time: float, model_note: str = '') -> dict:
    """Success per shape and overall, times to grasp (s), real-time factor."""
    by_shape = {}
    counts = {}
    for shape in SHAPES:
        rs = [r for r in records if r.shape == shape]
        by_shape[shape] = (sum(r.success for r in rs) / len(rs)) if rs else math.nan
        counts[shape] = {'trials': len(rs), 'successes': sum(r.success for r in rs)}
    times = [r.time_to_grasp for r in records if r.success and math.isfinite(r.time_to_grasp)]
    vision = [v for o in outcomes for v in o.vision_times]
    n = len(records)
    shape_known = [r for r in records if r.detected_shape != 'unknown']
    return {
        'trials': n,
        'seed': seed,
        'successes': sum(r.success for r in records),
        'success_rate': (sum(r.success for r in records) / n) if n else math.nan,
        'success_by_shape': by_shape,
        'counts_by_shape': counts,
        'mean_time_s': statistics.fmean(times) if times else math.nan,
        'median_time_s': statistics.median(times) if times else math.nan,
        'sim_time_s': sim_time,
        'wall_time_s': wall,
        'real_time_factor': sim_time / wall if wall > 0 else math.nan,
        'vision_ms_per_frame': 1e3 * statistics.fmean(vision) if vision else math.nan,
        'shape_model': model_note,
        'shape_accuracy': (sum(r.detected_shape == r.shape for r in shape_known)
                           / len(shape_known)) if shape_known else math.nan,
        'results': [asdict(r) for r in records],
    }
