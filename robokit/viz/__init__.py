"""Visualisation: meshcat 3D scenes that work live and as static offline HTML."""
from .scene import Scene, viewer_javascript

__all__ = ["Scene", "viewer_javascript"]
