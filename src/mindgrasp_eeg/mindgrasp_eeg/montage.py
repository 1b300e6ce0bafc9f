"""Channel montage and motor-imagery class names shared by the EEG package.

The default montage is the 32-channel g.tec g.Nautilus 10-20 layout used in the MIndGrasp paper;
names follow MNE's ``standard_1020`` spelling so ``mne.channels.make_standard_montage`` finds every
position.
"""

from __future__ import annotations

#: 32 channels of a g.Nautilus-like 10-20 cap, in stream order.
NAUTILUS_32: tuple[str, ...] = (
    'Fp1', 'Fp2', 'AF3', 'AF4', 'F7', 'F3', 'Fz', 'F4', 'F8', 'FC5', 'FC1', 'FC2', 'FC6',
    'T7', 'C3', 'Cz', 'C4', 'T8', 'CP5', 'CP1', 'CP2', 'CP6', 'P7', 'P3', 'Pz', 'P4', 'P8',
    'PO3', 'PO4', 'O1', 'Oz', 'O2',
)

#: Default sampling rate of the g.Nautilus in the paper (Hz).
NAUTILUS_RATE = 250.0

#: Motor-imagery classes (index = ``MIPrediction.class_index``).
CLASS_NAMES: tuple[str, ...] = ('left_hand', 'right_hand', 'both_hands', 'both_feet')
LEFT_HAND, RIGHT_HAND, BOTH_HANDS, BOTH_FEET = 0, 1, 2, 3
#: ``Prompt.NO_CLASS``: fixation / rest.
NO_CLASS = 255


def class_name(index: int | None) -> str:
    """Name of a class index; ``'rest'`` for ``None`` or :data:`NO_CLASS`."""
    if index is None or index == NO_CLASS:
        return 'rest'
    return CLASS_NAMES[index]
