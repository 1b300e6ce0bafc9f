"""Channel montage of the EEG package, and the motor-imagery classes (from mindgrasp_common).

The default montage is the 32-channel g.tec g.Nautilus 10-20 layout used in the MIndGrasp paper;
names follow MNE's ``standard_1020`` spelling so ``mne.channels.make_standard_montage`` finds every
position.
"""

from __future__ import annotations

from mindgrasp_common.mi import CLASS_NAMES, NO_CLASS, MiClass, class_name

__all__ = ['BOTH_FEET', 'BOTH_HANDS', 'CLASS_NAMES', 'LEFT_HAND', 'NAUTILUS_32', 'NAUTILUS_RATE',
           'NO_CLASS', 'RIGHT_HAND', 'class_name']

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
