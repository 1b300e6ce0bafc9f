"""Channel montage of the EEG package, and the motor-imagery classes (from mindgrasp_common).

The default montage is the 32-channel g.tec g.Nautilus 10-20 layout used in the MIndGrasp paper;
names follow MNE's 10-20 spelling so :func:`standard_montage` finds every position.
"""

from __future__ import annotations

from mindgrasp_common.mi import CLASS_NAMES, NO_CLASS, MiClass, class_name

__all__ = ['BOTH_FEET', 'BOTH_HANDS', 'CLASS_NAMES', 'LEFT_HAND', 'NAUTILUS_32', 'NAUTILUS_RATE',
           'NO_CLASS', 'RIGHT_HAND', 'class_name', 'standard_montage', 'standard_montage_name']

#: 32 channels of a g.Nautilus-like 10-20 cap, in stream order.
NAUTILUS_32: tuple[str, ...] = (
    'Fp1', 'Fp2', 'AF3', 'AF4', 'F7', 'F3', 'Fz', 'F4', 'F8', 'FC5', 'FC1', 'FC2', 'FC6',
    'T7', 'C3', 'Cz', 'C4', 'T8', 'CP5', 'CP1', 'CP2', 'CP6', 'P7', 'P3', 'Pz', 'P4', 'P8',
    'PO3', 'PO4', 'O1', 'Oz', 'O2',
)

#: Default sampling rate of the g.Nautilus in the paper (Hz).
NAUTILUS_RATE = 250.0

#: Motor-imagery class indices (``MIPrediction.class_index``), as plain ints
LEFT_HAND, RIGHT_HAND, BOTH_HANDS, BOTH_FEET = (int(c) for c in MiClass)


def standard_montage_name() -> str:
    """MNE's name of the standard 10-20 positions: ``colin27_1020`` since MNE 1.13, which
    deprecated ``standard_1020`` (the same positions) with a FutureWarning on every export."""
    import mne

    return 'colin27_1020' if 'colin27_1020' in mne.channels.get_builtin_montages() \
        else 'standard_1020'


def standard_montage():
    """The standard 10-20 electrode positions (an ``mne.channels.DigMontage``, metres)."""
    import mne

    return mne.channels.make_standard_montage(standard_montage_name())
