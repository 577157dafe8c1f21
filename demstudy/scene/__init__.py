"""Scene files: schema, validation, loading (dimensionless particle units: d = m = 1, g = 1)."""

from .load import (
    SceneError,
    apply_overrides,
    apply_sections,
    flat_fields,
    load_scene,
    parse_scene_text,
    scene_to_toml,
    validate_scene,
)
from .presets import list_presets, preset_path
from .scene import Scene

__all__ = [
    "Scene",
    "SceneError",
    "apply_overrides",
    "apply_sections",
    "flat_fields",
    "list_presets",
    "load_scene",
    "parse_scene_text",
    "preset_path",
    "scene_to_toml",
    "validate_scene",
]
