"""Scene files: schema, validation, loading (dimensionless particle units: d = m = 1, g = 1)."""

from .load import (
    SceneError,
    apply_overrides,
    load_scene,
    parse_scene_text,
    scene_to_toml,
    validate_scene,
)
from .scene import Scene

__all__ = [
    "Scene",
    "SceneError",
    "apply_overrides",
    "load_scene",
    "parse_scene_text",
    "scene_to_toml",
    "validate_scene",
]
