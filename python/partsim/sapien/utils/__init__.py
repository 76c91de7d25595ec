"""SAPIEN's `sapien.utils` on partsim: the viewer, which runs in a web browser."""

from __future__ import annotations

from ... import _partsim as _p
from .._adapter import PartsimError, unwrap


class Viewer(_p.Viewer):
    """The browser viewer, taking SAPIEN's arguments too: Viewer(scene, port=0, ...) as
    partsim's, or SAPIEN 2's Viewer(renderer, shader_dir="", resolutions=...) followed by
    viewer.set_scene(scene) (the renderer, shader folder and window size are ignored: the page
    draws in the browser)."""

    def __init__(self, scene=None, *args, shader_dir=None, resolutions=None, **kwargs):
        if scene is not None and not isinstance(unwrap(scene), _p.Scene):
            scene, args = None, ()  # SAPIEN: a renderer, then shader_dir and resolutions
        super().__init__(unwrap(scene), *args, **kwargs)

    def set_scene(self, scene):
        super().set_scene(unwrap(scene))

    def toggle_axes(self, show):
        """SAPIEN's viewer.toggle_axes: accepted, no effect (the page has its own toggles)."""

    def toggle_camera_lines(self, show):
        """SAPIEN's viewer.toggle_camera_lines: accepted, no effect (the page has its own
        toggles)."""

    def create_window(self, *args, **kwargs):
        raise PartsimError("no on-screen window: the viewer runs in a web browser; open the "
                           "URL it printed")


from . import viewer  # noqa: E402,F401  (sapien.utils.viewer.Viewer)
