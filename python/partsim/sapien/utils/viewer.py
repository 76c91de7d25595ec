"""SAPIEN 2's `sapien.utils.viewer`: the browser viewer."""

from . import Viewer  # noqa: F401
