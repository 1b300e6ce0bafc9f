"""The pygame window that shows the participant's frames (or an off-screen surface, headless).

Headless runs use SDL's ``dummy`` video driver: the same surface is drawn and flipped, nothing
appears on a screen, and no display server is needed. A windowed run without a display fails
at once with a message that suggests ``--headless``.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from mindgrasp_trainer.protocol import TrainerError

__all__ = ['NO_DISPLAY', 'Window']

NO_DISPLAY = ('No display is available for the participant window ({why}); run the display '
              'with --headless (frames go to /display/image and PNG files) or start it from a '
              'desktop session (or under xvfb-run).')


class Window:
    """A pygame window of a fixed size, or an off-screen one.

    Parameters
    ----------
    width, height : int
        Frame size (px). Full screen shows the frame at this size in the middle of the screen.
    fullscreen : bool
        Take the whole screen (Esc or closing the window ends the display).
    headless : bool
        Draw off-screen (SDL ``dummy`` video driver).
    title : str
        Window title.
    """

    def __init__(self, width: int, height: int, fullscreen: bool = False,
                 headless: bool = False, title: str = 'MIndGrasp') -> None:
        if headless:
            os.environ['SDL_VIDEODRIVER'] = 'dummy'
        elif (sys.platform.startswith('linux') and not os.environ.get('DISPLAY')
              and not os.environ.get('WAYLAND_DISPLAY')):
            raise TrainerError(NO_DISPLAY.format(why='DISPLAY and WAYLAND_DISPLAY are not set'))
        os.environ.setdefault('PYGAME_HIDE_SUPPORT_PROMPT', '1')
        import pygame

        self._pg = pygame
        try:
            pygame.display.init()
            flags = pygame.FULLSCREEN if fullscreen and not headless else 0
            size = (0, 0) if flags else (int(width), int(height))
            self.surface = pygame.display.set_mode(size, flags)
        except pygame.error as err:
            pygame.display.quit()
            raise TrainerError(NO_DISPLAY.format(why=f'SDL: {err}')) from None
        pygame.display.set_caption(title)
        pygame.mouse.set_visible(not fullscreen)
        self.width, self.height = int(width), int(height)
        self.headless = headless
        self.closed = False

    def show(self, frame: np.ndarray) -> int:
        """Draw ``frame`` (uint8, shape (height, width, 3), RGB) and flip.

        Returns
        -------
        flip_ns : int
            ``time.monotonic_ns()`` right after the flip returned (ns).
        """
        pg = self._pg
        h, w = frame.shape[:2]
        image = pg.image.frombuffer(np.ascontiguousarray(frame).tobytes(), (w, h), 'RGB')
        sw, sh = self.surface.get_size()
        if (sw, sh) != (w, h):
            self.surface.fill((0, 0, 0))
        self.surface.blit(image, ((sw - w) // 2, (sh - h) // 2))
        pg.display.flip()
        return time.monotonic_ns()

    def poll(self) -> bool:
        """Handle window events; False once the participant closed the window or pressed Esc."""
        pg = self._pg
        for event in pg.event.get():
            if event.type == pg.QUIT or (event.type == pg.KEYDOWN and event.key == pg.K_ESCAPE):
                self.closed = True
        return not self.closed

    def close(self) -> None:
        self._pg.display.quit()
