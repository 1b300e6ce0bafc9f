"""Parsers of structured launch-argument text (ROS-free): the text is parsed, never evaluated.

``camera:=640x480@30`` used to be pasted into a ``PythonExpression``; any text a user types into a
launch argument now goes through a small explicit parser that accepts exactly the documented
form and names it in its error.
"""

from __future__ import annotations

import re

__all__ = ['CAMERA_FIELDS', 'parse_camera']

#: the fields of a camera spec, in order
CAMERA_FIELDS = ('width', 'height', 'rate')

_CAMERA = re.compile(r'(\d{1,5})x(\d{1,5})@(\d{1,4}(?:\.\d{1,6})?)')


def parse_camera(text: str) -> tuple[int, int, float]:
    """``'WIDTHxHEIGHT@HZ'`` (e.g. ``'640x480@30'``) -> (width px, height px, rate Hz).

    Raises
    ------
    ValueError
        Anything else, with the expected form and an example.
    """
    match = _CAMERA.fullmatch(text.strip())
    if match is None:
        msg = (f'camera:={text!r} is not WIDTHxHEIGHT@HZ (whole numbers of pixels, a rate in '
               'Hz), e.g. camera:=640x480@30.')
        raise ValueError(msg)
    width, height, rate = int(match[1]), int(match[2]), float(match[3])
    if width < 1 or height < 1 or rate <= 0:
        msg = (f'camera:={text!r}: width, height and rate must be positive, e.g. '
               'camera:=640x480@30.')
        raise ValueError(msg)
    return width, height, rate
