"""Parameters of the EEG nodes, declared once (units, ranges, descriptions).

Each field is a ROS parameter of its node (:func:`mindgrasp_ros.params.param`);
``config/param/eeg.yaml`` holds the same names and defaults under ``eeg_acquisition:`` and
``virtual_amp:``. All are read-only: the inlet, outlet, generator and subject are built from them
at start, so a change needs a restart.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mindgrasp_common.resources import resource_path
from mindgrasp_eeg.acquisition import NAN_POLICIES
from mindgrasp_eeg.montage import NAUTILUS_32
from mindgrasp_eeg.subject import MODES
from mindgrasp_ros.params import param

__all__ = ['OUTPUTS', 'AcquisitionParams', 'MarkerParams', 'VirtualAmpParams',
           'default_params_path']

#: ``output`` of the virtual amplifier: an LSL stream (live runs) or /eeg/raw (lock-step)
OUTPUTS = ('lsl', 'ros')
_STREAM = 'MIndGrasp-VirtualAmp'


def default_params_path() -> Path:
    """This package's ``param/eeg.yaml``."""
    return resource_path('mindgrasp_eeg', 'param', 'eeg.yaml')


@dataclass
class AcquisitionParams:
    """Parameters of the acquisition node (``eeg_acquisition``): which LSL stream, its expected
    layout, and how /eeg/raw and /eeg/status are published."""

    stream_name: str = param(_STREAM, "LSL stream name (a real amplifier: its LSL app's name)")
    stream_type: str = param('', "also match this LSL type, e.g. EEG ('' = any)")
    source_id: str = param('', "also match this LSL source_id ('' = any)")
    hostname: str = param('', "also match the sender's host ('' = any, local = this host)")
    allow_unpinned: bool = param(True, 'false: refuse to start unless source_id and hostname '
                                 'pin the sender (the hardware profile)')
    n_channels: int = param(32, 'expected channel count (0 = the stream\'s)', min=0)
    sample_rate: float = param(250.0, "expected sample rate (0 = the stream's)", unit='Hz',
                               min=0.0)
    channel_names: list[str] = param(list(NAUTILUS_32), 'expected channel labels')
    check_channel_names: bool = param(True, 'false: accept any labels (count and rate still '
                                      'checked)')
    adapt_to_stream: bool = param(False, "adopt the stream's layout with a warning on a "
                                  'mismatch')
    stream_unit: str = param('auto', 'unit of the stream values: auto (channel metadata, else '
                             'microvolts), microvolts, V, ...')
    chunk_period: float = param(1.0 / 32.0, 'period of the connection, status-level and marker '
                                'checks (/eeg/raw goes out as each block arrives)', unit='s',
                                min=1e-3, max=10.0)
    max_buflen: float = param(1.0, 'LSL inlet buffer bound: no stale backlog after a stall',
                              unit='s', min=1e-3)
    resolve_timeout: float = param(30.0, 'wait this long for the stream, then exit with the '
                                   'streams seen', unit='s', min=0.0)
    lost_timeout: float = param(0.5, 'no samples this long = stream lost (reconnect)', unit='s',
                                min=1e-3)
    nan_policy: str = param('replace', 'non-finite values: replace (last finite value), drop '
                            '(samples) or keep', choices=NAN_POLICIES)
    dejitter: bool = param(True, 'LSL timestamp smoothing')
    clocksync: bool = param(True, 'LSL clock offset correction')
    quality_window: float = param(1.0, 'window of the flat / railed checks', unit='s',
                                  min=1e-3)
    flat_threshold: float = param(1e-7, 'std below this over the window = flat channel',
                                  unit='V', min=0.0)
    rail_threshold: float = param(0.1, '|x| at or above this in > 10 % of the window = railed',
                                  unit='V', min=0.0)
    status_period: float = param(1.0, '/eeg/status period (also sent on every level change)',
                                 unit='s', min=1e-3, max=3600.0)
    frame_id: str = param('eeg', 'frame_id of /eeg/raw')
    marker_stream: str = param('none', 'LSL marker stream relayed to /eeg/markers: none, auto '
                               '(<stream_name>-markers, as `mindgrasp eeg play` names it) or its '
                               'name')
    duration: float = param(0.0, 'end after this long (0 = until stopped)', unit='s', min=0.0)


@dataclass
class VirtualAmpParams:
    """Parameters of the virtual amplifier node (``virtual_amp``): the stream, the virtual subject
    and the synthetic EEG (amplitudes in volts)."""

    stream_name: str = param(_STREAM, 'LSL stream name (output lsl)')
    stream_type: str = param('EEG', 'LSL stream type')
    source_id: str = param('', "LSL source_id ('' = <stream_name>@<run directory name> in "
                           'a launch, else the stream name)')
    channel_names: list[str] = param(list(NAUTILUS_32), 'channel labels (10-20 names)')
    sample_rate: float = param(250.0, 'sample rate (the synthetic EEG needs >= 60 Hz)',
                               unit='Hz', min=60.0, max=100000.0)
    unit: str = param('microvolts', 'unit of the LSL values (declared in the stream metadata)')
    reference: str = param('', "EEG reference declared in the stream metadata (<acquisition>"
                           "<reference>), e.g. Cz ('' = none declared)")
    subject_mode: str = param('noise', 'noise | follow (/trainer/prompt) | pursue (task, scene, '
                              'arm, fsm)', choices=MODES)
    accuracy: float = param(0.9, 'probability of imagining the right class', min=0.0, max=1.0)
    reaction_delay: float = param(0.5, 'from prompt / decision to imagery onset', unit='s',
                                  min=0.0)
    lapse_rate: float = param(0.0, 'follow: probability of not imagining a prompted trial',
                              min=0.0, max=1.0)
    active_phases: list[str] = param(['cue', 'move', 'wait'], 'follow: phases with imagery')
    decision_period: float = param(0.5, 'pursue: time between decisions', unit='s', min=1e-3)
    heading_tolerance: float = param(0.1, 'pursue: heading error taken as centred', unit='rad',
                                     min=0.0)
    robot: str = param('', "pursue: the arm (robot:= of the launch): its first joint, turning "
                       "direction and home give the heading; '' = base_joint's angle is the "
                       'heading')
    base_joint: str = param('', "pursue: joint giving the arm heading ('' = the robot's first "
                            'joint, or the first joint of /joint_states)')
    base_position: list[float] = param([0.0, 0.0], 'pursue: arm base in the /sim/objects frame',
                                       unit='m')
    heading_offset: float = param(0.0, 'pursue: added to the arm heading', unit='rad',
                                  min=-6.3, max=6.3)
    seed: int = param(0, 'seed of the EEG time series and the subject decisions', min=0)
    head_seed: int = param(0, 'seed of the head model (keep it for one virtual subject)', min=0)
    # decodability (mindgrasp_eeg.synthetic; fitted to a real subject by `mindgrasp eeg
    # fit-virtual`, which writes these as a parameter file); 1, 1, 0, 0 is the original head
    separability: float = param(1.0, 'scale of every class ERD (0: classes indistinguishable)',
                                min=0.0, max=10.0)
    lateral_separability: float = param(1.0, 'how one-sided one-hand imagery is (0: left = '
                                        'right)', min=0.0, max=1.0)
    rest_separability: float = param(0.0, 'occipital alpha drop with any imagery, times '
                                     'erd_depth', min=0.0, max=10.0)
    nonstationarity: float = param(0.0, 'drift between runs and stretches (0: stationary)',
                                   min=0.0, max=10.0)
    background_rms: float = param(10e-6, '1/f background', unit='V', min=0.0)
    alpha_rms: float = param(8e-6, 'alpha rhythm', unit='V', min=0.0)
    mu_rms: float = param(6e-6, 'mu rhythm', unit='V', min=0.0)
    beta_rms: float = param(3e-6, 'beta rhythm', unit='V', min=0.0)
    sensor_noise_rms: float = param(0.5e-6, 'sensor noise', unit='V', min=0.0)
    erd_depth: float = param(0.5, 'mu/beta amplitude drop during imagery (0.5 = -75 % power)',
                             min=0.0, max=1.0)
    erd_tau: float = param(0.3, 'ERD onset / offset time constant', unit='s', min=0.0)
    blink_rate: float = param(0.0, 'blinks per second (0 = off; ~0.25 is natural)', unit='Hz',
                              min=0.0)
    blink_amplitude: float = param(100e-6, 'blink amplitude at Fp1/Fp2', unit='V', min=0.0)
    emg_rate: float = param(0.0, 'EMG bursts per second (0 = off)', unit='Hz', min=0.0)
    emg_rms: float = param(20e-6, 'EMG at T7/T8', unit='V', min=0.0)
    line_noise: float = param(0.0, 'mains interference (0 = off)', unit='V', min=0.0)
    line_freq: float = param(50.0, 'mains frequency', unit='Hz', min=0.0)
    push_period: float = param(1.0 / 32.0, 'time between pushes', unit='s', min=1e-3, max=10.0)
    block: int = param(8, 'samples per imagery decision / push', min=1)
    duration: float = param(0.0, 'end after this long (0 = until stopped)', unit='s', min=0.0)
    output: str = param('lsl', "lsl (an LSL stream, live runs) or ros (/eeg/raw on the node "
                        'clock, lock-step experiments)', choices=OUTPUTS)
    frame_id: str = param('eeg', 'frame_id of /eeg/raw (output ros)')
    eeg_source: str = param('synthetic', 'synthetic (head model) | eegmmidb:<subject> | '
                            'path/to/subject.yaml (real imagery epochs of a replay subject, '
                            'mindgrasp_eeg.subject_file)')


@dataclass
class MarkerParams:
    """Parameters of the LSL marker node (``lsl_markers``): the outlet LabRecorder records and
    where the cue times come from."""

    stream_name: str = param('MIndGrasp-Markers', 'LSL name of the marker stream')
    source_id: str = param('mindgrasp-markers', 'LSL source_id (stable: LabRecorder and other '
                           'inlets find the stream again after a restart)')
    cue_topic: str = param('/trainer/prompt', "prompts to mirror: /trainer/prompt (the "
                           "trainer's time) or /display/flip (the display's flip time, when a "
                           'display runs)')
    duration: float = param(0.0, 'end after this long (0 = until stopped)', unit='s', min=0.0)
