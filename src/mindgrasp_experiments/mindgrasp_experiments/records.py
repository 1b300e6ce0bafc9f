"""One trial record, one success definition and one outcome per trial, for the trial manager.

A grasp trial succeeds when an object is lifted above :data:`SUCCESS_HEIGHT` (0.22 m, the original
MIndGrasp code's threshold); the simulator's task monitor reports that lift on ``/task/result``
(``GraspResult.success``). The choice is correct when the object the controller went for is the
desired one. What the trial achieved for the person is its outcome (:func:`outcome_of`), exactly
one of :data:`OUTCOMES`: ``correct_grasp``, ``wrong_grasp`` or ``no_grasp``.

:class:`TrialTracker` (ROS-free) turns what the trial manager node hears during a trial
(controller states, predictions, the subject's intent, the end-effector pose, the grasp result)
into a :class:`TrialRecord`; :func:`write_records` stores them as CSV and Parquet.

    >>> tracker = TrialTracker()
    >>> tracker.start(trial=1, desired='red cube', desired_id=0, t=10.0)
    >>> tracker.on_state(5, 'red cube', t=30.0)
    >>> tracker.on_result('red cube', True, t=33.0)
    >>> rec = tracker.finish(t=40.0)
    >>> rec.correct_and_successful, rec.outcome
    (True, 'correct_grasp')
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from mindgrasp_common.mi import CLASS_NAMES, DECODER_CLASS_NAMES, REST
from mindgrasp_common.safe_files import write_atomic
from mindgrasp_common.states import State
from mindgrasp_sim.task import SUCCESS_HEIGHT

__all__ = ['FAILURES', 'OUTCOMES', 'SUCCESS_HEIGHT', 'TrialRecord', 'TrialTracker',
           'is_cancel', 'outcome_of', 'read_records', 'write_records']

#: why a trial ended without a grasp result ('' = it ended normally)
FAILURES = ('', 'no_grasp', 'dropped', 'timeout', 'stalled', 'node_error', 'interrupted')

#: what a trial achieved for the person (:func:`outcome_of`)
OUTCOMES = ('correct_grasp', 'wrong_grasp', 'no_grasp')

#: columns of older records files under their present name
_RENAMED = {'decoder_accuracy': 'online_accuracy'}

#: controller states in the order a grasp attempt ends without a lift: the grasp (or the final
#: approach) gave up, the arm returned, the search began again
_ATTEMPT_ENDS = ([State.GRASP_OBJECT, State.RETURN_TO_START, State.OBJECT_SEARCH],
                 [State.FINAL_APPROACH, State.RETURN_TO_START, State.OBJECT_SEARCH])


@dataclass
class TrialRecord:
    """One grasp trial. Times are simulated (node-clock) seconds; positions metres in the world
    frame (arm base at the origin); labels ``"<colour> <shape>"``.

    ``outcome`` is set by :meth:`TrialTracker.finish`; a record made without one (a trial that
    failed before it began, a records file older than the column) gets :func:`outcome_of` of its
    other fields."""

    trial: int                       # 1-based trial number
    protocol: str = ''               # set_locations | random_locations | demo
    subject: str = ''                # noise | virtual | oracle | autonomous | ...
    seed: int = 0
    desired: str = ''                # the object the subject was asked to grasp
    desired_id: int = -1             # its id in /sim/objects
    desired_x: float = math.nan      # its position at the start of the trial (m)
    desired_y: float = math.nan
    n_objects: int = 0               # objects in the scene at the start (0: not known)
    chosen: str = ''                 # the controller's object of interest when it began to
                                     # grasp: colour + shape CNN, as the paper names it
    grasped: str = ''                # ground truth: the object lifted (or last dropped; '' none)
    success: bool = False            # an object was lifted above SUCCESS_HEIGHT
    correct_choice: bool = False     # the object gone for is the desired one
    correct_and_successful: bool = False
    outcome: str = ''                # one of OUTCOMES (outcome_of)
    lift_height: float = math.nan    # m, highest lift of the grasped object (centre height)
    time_to_grasp_s: float = math.nan   # from the target to the successful lift
    duration_s: float = 0.0          # from the target to the end of the trial
    states: str = ''                 # controller states visited, in order ("1-2-3-4-5-6")
    cancels: int = 0                 # returns to start the person cancelled (is_cancel)
    path_length_m: float = 0.0       # end-effector path length
    class_switches: int = 0          # changes of the decoded class
    n_predictions: int = 0
    online_accuracy: float = math.nan   # decoder_hits / decoder_windows (NaN: none judged)
    decoder_windows: int = 0         # predictions (classifier windows) judged against an intent
    decoder_hits: int = 0            #   ... of which equal to the intent
    decoder_decisions: int = 0       # spans of one held intent with judged predictions in them
    decoder_decision_hits: int = 0   #   ... whose most frequent predicted class is the intent
    mean_certainty: float = math.nan
    failure: str = ''                # one of FAILURES
    reason: str = ''                 # how the trial ended, in words
    answer_pair: str = ''            # scan: the person's answer pair (hands_feet, left_right, ...)

    def __post_init__(self) -> None:
        if not self.outcome:
            self.outcome = outcome_of(self)
        elif self.outcome not in OUTCOMES:
            msg = f'Unknown trial outcome {self.outcome!r}; use one of {OUTCOMES}.'
            raise ValueError(msg)

    @classmethod
    def columns(cls) -> list[str]:
        return [f.name for f in fields(cls)]

    def to_row(self) -> dict:
        return asdict(self)


def outcome_of(rec: TrialRecord) -> str:
    """What the trial achieved for the person who uses the arm, one of :data:`OUTCOMES`:

    - ``correct_grasp``: the desired object was lifted above :data:`SUCCESS_HEIGHT`
      (``correct_and_successful``);
    - ``wrong_grasp``: another object was lifted, or a grasp closed on another object even if
      nothing was lifted: the controller entered state 5 (GRASP_OBJECT) with an object of
      interest that is not the desired one (``chosen``), or an object other than the desired one
      was lifted and dropped (``grasped``, ground truth, wins over the controller's label);
    - ``no_grasp``: everything else: a timeout, a stall, the person cancelled the approach (the
      controller returned to start without entering state 5), nothing was attempted, the
      desired object slipped, or the trial was interrupted (Ctrl-C: cut off by the operator,
      whatever it had attempted; interrupted trials are left out of every rate).

    A lift ends the trial, so a lift decides the outcome whatever was attempted before it.

        >>> outcome_of(TrialRecord(1, desired='red cube', chosen='blue cube'))
        'wrong_grasp'
        >>> outcome_of(TrialRecord(1, desired='red cube', chosen='blue cube',
        ...                        failure='interrupted'))
        'no_grasp'
    """
    if rec.success:
        return 'correct_grasp' if rec.correct_and_successful else 'wrong_grasp'
    if rec.failure == 'interrupted':
        return 'no_grasp'
    gone_for = rec.grasped or rec.chosen
    return 'wrong_grasp' if gone_for and gone_for != rec.desired else 'no_grasp'


def is_cancel(reason: str) -> bool:
    """Whether a ``/fsm/state`` reason says the person cancelled: it starts with ``cancelled``
    (also while the joints are locked for the transition: ``locked: cancelled ...``).

        >>> is_cancel('cancelled by both feet'), is_cancel('locked: cancelled'), is_cancel('')
        (True, True, False)
    """
    text = reason.strip().lower()
    text = text.removeprefix('locked:').strip()
    return text.startswith('cancelled')


def _label_shape(label: str) -> str:
    return label.rpartition(' ')[2]


def _intent_index(name: str) -> int | None:
    """Class index of an intent as ``/virtual_subject/intent`` names it: an imagery class,
    :data:`~mindgrasp_common.mi.REST` for ``rest`` or an empty intent, None for anything else."""
    key = name.strip().lower().replace(' ', '_').replace('-', '_')
    if key in ('', 'rest'):
        return REST
    return CLASS_NAMES.index(key) if key in CLASS_NAMES else None


class TrialTracker:
    """Builds the :class:`TrialRecord` of the running trial from what a trial manager hears.

    Call :meth:`start` when the target is named, the ``on_*`` methods as messages arrive (``t``:
    node-clock seconds), and :meth:`finish` when the trial ends; :attr:`attempt_over` says when
    a grasp attempt ended without a lift.
    """

    def __init__(self, protocol: str = '', subject: str = '', seed: int = 0) -> None:
        self.protocol, self.subject, self.seed = protocol, subject, seed
        self.record: TrialRecord | None = None
        self._t0 = 0.0
        self._states: list[int] = []
        self._cancelled: set[int] = set()  # indices in _states of returns the person cancelled
        self._cancel_pending = False       # a cancel announced while the joints are locked
        self._last_pos: tuple[float, float, float] | None = None
        self._intent: int | None = None
        self._last_class: int | None = None
        self._certainties: list[float] = []
        self._hits = 0
        self._judged = 0
        self._span: dict[int, int] = {}    # predicted class -> count, in the current intent span
        self.last_state_change = 0.0

    @property
    def active(self) -> bool:
        return self.record is not None

    @property
    def start_time(self) -> float:
        """When the current trial started (s, node clock; 0 before the first)."""
        return self._t0

    @property
    def attempt_over(self) -> bool:
        """A grasp attempt ended without a lift: the controller went from the grasp (or the
        final approach) back to start and on to the search. A return the person cancelled is
        not the end of an attempt: the trial goes on (a later attempt may grasp)."""
        s = self._states
        return (len(s) >= 3 and s[-3:] in _ATTEMPT_ENDS
                and len(s) - 2 not in self._cancelled)

    def start(self, trial: int, desired: str, desired_id: int = -1, t: float = 0.0,
              desired_xy: Sequence[float] = (math.nan, math.nan), state: int = 0,
              n_objects: int = 0) -> None:
        """A new trial: the target ``desired`` is named at time ``t`` (s) in a scene of
        ``n_objects`` objects (0: not known)."""
        self.record = TrialRecord(trial=trial, protocol=self.protocol, subject=self.subject,
                                  seed=self.seed, desired=desired, desired_id=desired_id,
                                  desired_x=float(desired_xy[0]), desired_y=float(desired_xy[1]),
                                  n_objects=int(n_objects))
        self._t0 = t
        self._states = [state] if state else []
        self._cancelled = set()
        self._cancel_pending = False
        self._last_pos = None
        self._last_class = None
        self._certainties = []
        self._hits = self._judged = 0
        self._span = {}
        self.last_state_change = t

    def on_state(self, state: int, object_of_interest: str, t: float, reason: str = '') -> None:
        """``/fsm/state``: records the states visited, the object chosen for the grasp, and
        the returns to start the person cancelled (``reason``: :func:`is_cancel`)."""
        if self.record is None:
            return
        cancel = is_cancel(reason)
        if not self._states or self._states[-1] != state:
            self._states.append(state)
            self.last_state_change = t
            if state == State.RETURN_TO_START and (cancel or self._cancel_pending):
                self._cancelled.add(len(self._states) - 1)
                self.record.cancels += 1
            self._cancel_pending = False
        elif cancel and state != State.RETURN_TO_START:
            # the controller announces the cancel while its joints are locked; the return follows
            self._cancel_pending = True
        if state == State.GRASP_OBJECT and not self.record.chosen and object_of_interest:
            self.record.chosen = object_of_interest

    def on_prediction(self, class_index: int, certainty: float, t: float,
                      class_names: Sequence[str] = ()) -> None:
        """``/bci/prediction``: class switches, online accuracy against the intent, certainty.

        A window is judged against the subject's intent when the intent is a class the model
        knows (``class_names``, ``MIPrediction.class_names``; empty: the four imagery classes):
        a ``rest`` intent counts when the model knows ``rest``, and is left out otherwise."""
        if self.record is None:
            return
        rec = self.record
        rec.n_predictions += 1
        if self._last_class is not None and class_index != self._last_class:
            rec.class_switches += 1
        self._last_class = class_index
        if math.isfinite(certainty):
            self._certainties.append(float(certainty))
        known = {n.strip().lower() for n in class_names} if class_names else set(CLASS_NAMES)
        if self._intent is not None and DECODER_CLASS_NAMES[self._intent] in known:
            self._judged += 1
            self._hits += int(class_index == self._intent)
            self._span[class_index] = self._span.get(class_index, 0) + 1

    def on_intent(self, name: str) -> None:
        """``/virtual_subject/intent``: the class the subject imagines (``rest`` or empty: rest;
        an unknown name: none)."""
        intent = _intent_index(name)
        if intent != self._intent:
            self._close_span()
        self._intent = intent

    def _close_span(self) -> None:
        """One decision of the decoder: its most frequent class over the span of one held
        intent (ties: the lower class index), judged against that intent."""
        if self.record is not None and self._span and self._intent is not None:
            decided = max(sorted(self._span), key=self._span.__getitem__)
            self.record.decoder_decisions += 1
            self.record.decoder_decision_hits += int(decided == self._intent)
        self._span = {}

    def on_ee_pose(self, x: float, y: float, z: float) -> None:
        """``/ee_pose``: adds to the path length (m)."""
        if self.record is None:
            return
        if self._last_pos is not None:
            lx, ly, lz = self._last_pos
            self.record.path_length_m += math.sqrt((x - lx) ** 2 + (y - ly) ** 2 + (z - lz) ** 2)
        self._last_pos = (x, y, z)

    def on_result(self, grasped: str, success: bool, t: float,
                  lift_height: float = math.nan) -> None:
        """``/task/result``: a lift above the success height, or a drop. A drop does not end the
        trial (the controller may grasp again); the first lift counts."""
        rec = self.record
        if rec is None or rec.success:
            return
        rec.grasped, rec.success, rec.lift_height = grasped, bool(success), float(lift_height)
        if success:
            rec.time_to_grasp_s = t - self._t0

    def finish(self, t: float, failure: str = '', reason: str = '') -> TrialRecord:
        """End the trial at ``t`` (s); returns its record."""
        if self.record is None:
            msg = 'TrialTracker.finish() called without a trial; call start() first.'
            raise RuntimeError(msg)
        if failure not in FAILURES:
            msg = f'Unknown trial failure {failure!r}; use one of {FAILURES}.'
            raise ValueError(msg)
        self._close_span()
        rec, self.record = self.record, None
        rec.duration_s = t - self._t0
        rec.decoder_windows, rec.decoder_hits = self._judged, self._hits
        rec.states = '-'.join(str(s) for s in self._states)
        rec.online_accuracy = self._hits / self._judged if self._judged else math.nan
        rec.mean_certainty = (math.fsum(self._certainties) / len(self._certainties)
                              if self._certainties else math.nan)
        # the object gone for: ground truth when something was lifted, else the controller's
        # named choice (colour + CNN shape)
        gone_for = rec.grasped or rec.chosen
        rec.correct_choice = bool(gone_for) and gone_for == rec.desired
        rec.correct_and_successful = rec.success and rec.grasped == rec.desired
        if rec.grasped and not rec.success and failure in ('', 'no_grasp'):
            failure = 'dropped'
            reason = (f'the {rec.grasped} was dropped after a lift to {rec.lift_height:.3f} m '
                      f'(success: above {SUCCESS_HEIGHT:.2f} m)')
        elif not failure and not rec.grasped:
            failure = 'no_grasp'
        rec.failure = failure
        rec.reason = reason or ('object lifted above '
                                f'{SUCCESS_HEIGHT:.2f} m' if rec.success else failure)
        rec.outcome = outcome_of(rec)
        return rec


def shape_of(label: str) -> str:
    """``"red cube"`` -> ``"cube"``."""
    return _label_shape(label)


def write_records(records: Iterable[TrialRecord], directory: str | Path,
                  stem: str = 'records') -> tuple[Path, Path]:
    """Write ``<directory>/<stem>.csv`` and ``.parquet`` (one row per trial, in trial order).

    Each file is written to a temporary name and renamed, so a full disk leaves the previous
    version intact, never a truncated file.

    Raises:
        OSError: a file could not be written (its previous version is unchanged).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rows = [r.to_row() for r in sorted(records, key=lambda r: r.trial)]
    columns = TrialRecord.columns()

    def write_csv(path: Path) -> None:
        with path.open('w', newline='', encoding='utf-8') as f:
            writer = csv.DictWriter(f, fieldnames=columns, lineterminator='\n')
            writer.writeheader()
            for row in rows:
                writer.writerow({k: _csv_value(v) for k, v in row.items()})

    table = pa.Table.from_pylist(rows, schema=_schema()) if rows else _schema().empty_table()
    csv_path = write_atomic(directory / f'{stem}.csv', write_csv)
    parquet_path = write_atomic(directory / f'{stem}.parquet',
                                lambda path: pq.write_table(table, path))
    return csv_path, parquet_path


def _csv_value(value: object) -> object:
    if isinstance(value, float):
        return '' if math.isnan(value) else repr(value)
    return value


def _schema():
    import pyarrow as pa

    types = {int: pa.int64(), float: pa.float64(), bool: pa.bool_(), str: pa.string()}
    return pa.schema([(f.name, types[eval_type(f.type)]) for f in fields(TrialRecord)])


def eval_type(annotation: object) -> type:
    """The builtin type of a TrialRecord field annotation (``'float'`` -> float)."""
    return {'int': int, 'float': float, 'bool': bool, 'str': str}[str(annotation)]


def read_records(path: str | Path) -> list[TrialRecord]:
    """Records from ``records.parquet`` or ``records.csv`` (a run directory: its parquet).

    Files of older versions are read too: ``decoder_accuracy`` is ``online_accuracy`` now, and
    a file without ``outcome`` gets :func:`outcome_of` of each record."""
    path = Path(path)
    if path.is_dir():
        path = path / 'records.parquet' if (path / 'records.parquet').exists() \
            else path / 'records.csv'
    if not path.exists():
        msg = (f'No trial records at {path}: give a run directory of mindgrasp experiment (with '
               'records.csv or records.parquet).')
        raise FileNotFoundError(msg)
    kinds = {f.name: eval_type(f.type) for f in fields(TrialRecord)}
    if path.suffix == '.parquet':
        import pyarrow.parquet as pq

        rows = pq.read_table(path).to_pylist()
    else:
        with path.open(encoding='utf-8') as f:
            rows = []
            for row in csv.DictReader(f):
                conv = {}
                for k, v in row.items():
                    kind = kinds.get(_RENAMED.get(k, k))
                    if kind is bool:
                        conv[k] = v == 'True'
                    elif kind is float:
                        conv[k] = float(v) if v != '' else math.nan
                    elif kind is int:
                        conv[k] = int(v)
                    elif kind is str:
                        conv[k] = v
                rows.append(conv)
    out = []
    for row in rows:
        for was, now in _RENAMED.items():
            if was in row and now not in row:
                row[now] = row.pop(was)
        clean = {k: (math.nan if kinds.get(k) is float and v is None else v)
                 for k, v in row.items() if k in kinds}
        out.append(TrialRecord(**clean))
    return out
