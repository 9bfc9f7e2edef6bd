"""Run inside a Python that has ``bpy`` (Blender as a module), not under pytest:

    python blender_check.py CONFIG.json RESULT.json

Installs the add-on zip the way a user does (*Install from Disk*:
``bpy.ops.preferences.addon_install``), enables it, runs ``import_scene.gnngarment`` on
each case in a factory-settings scene and writes what Blender shows to RESULT.json:
scene rate and range, the objects (type, parent, modifiers, vertex count) and every
mesh's evaluated world-space vertices at every frame of the range. The checks are in
``test_blender_addon.py``; this script only reports (it needs nothing but bpy and numpy,
no gnngarment).
"""

import json
import sys

import bpy  # first: it puts Blender's own modules (addon_utils) on sys.path
import numpy as np

# isort: split
import addon_utils

ADDON = "gnngarment_import"


def fresh_scene() -> None:
    """An empty factory scene (24 fps, frames 1–250) with the add-on enabled (factory
    settings reset the preferences, so it is enabled again each time)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if addon_utils.enable(ADDON, default_set=True, handle_error=None) is None:
        raise SystemExit(f"could not enable {ADDON}")


def world_vertices(obj, frame: int) -> list:
    scene = bpy.context.scene
    scene.frame_set(frame)
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    evaluated.to_mesh_clear()
    matrix = np.array(evaluated.matrix_world)
    return (co.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]).round(7).tolist()


def frame_range(action) -> list | None:
    return None if action is None else [float(v) for v in action.frame_range]


def describe_scene() -> dict:
    scene = bpy.context.scene
    objects = []
    for obj in scene.objects:
        if any(c.name.startswith("glTF_not_exported") for c in obj.users_collection):
            continue  # the importer's bone-shape helper, hidden and not exported
        entry = {"name": obj.name, "type": obj.type,
                 "parent": obj.parent.name if obj.parent else None,
                 "collections": [c.name for c in obj.users_collection],
                 "modifiers": [], "action": frame_range(
                     obj.animation_data.action if obj.animation_data else None)}
        for modifier in getattr(obj, "modifiers", []):
            entry["modifiers"].append({
                "type": modifier.type,
                "object": getattr(getattr(modifier, "object", None), "name", None),
                "filepath": getattr(modifier, "filepath", None),
                "frame_start": getattr(modifier, "frame_start", None),
                "cache_format": getattr(modifier, "cache_format", None)})
        if obj.type == "MESH":
            keys = obj.data.shape_keys
            entry["vertices"] = len(obj.data.vertices)
            entry["shape_keys"] = len(keys.key_blocks) if keys else 0
            entry["shape_key_action"] = frame_range(
                keys.animation_data.action if keys and keys.animation_data else None)
            entry["smooth"] = all(p.use_smooth for p in obj.data.polygons)
            entry["frames"] = [world_vertices(obj, frame) for frame in
                               range(scene.frame_start, scene.frame_end + 1)]
        objects.append(entry)
    return {"fps": scene.render.fps, "fps_base": scene.render.fps_base,
            "frame_start": scene.frame_start, "frame_end": scene.frame_end,
            "objects": objects}


def main(config_path: str, result_path: str) -> None:
    with open(config_path) as stream:
        config = json.load(stream)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.preferences.addon_install(filepath=config["zip"], overwrite=True)
    results: dict = {"blender": bpy.app.version_string, "cases": {}, "bad": {}}
    fresh_scene()
    menu = bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()  # the appended draw calls
    results["registered"] = {
        "operator": "gnngarment" in dir(bpy.ops.import_scene),
        "file_handler": hasattr(bpy.types, "IO_FH_gnngarment"),
        "menu": any(getattr(draw, "__module__", "") == ADDON for draw in menu)}
    addon_utils.disable(ADDON, default_set=True, handle_error=None)
    results["unregistered"] = {
        "operator": "gnngarment" in dir(bpy.ops.import_scene),
        "menu": any(getattr(draw, "__module__", "") == ADDON
                    for draw in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize())}
    for label, case in config["cases"].items():
        fresh_scene()
        outcome = bpy.ops.import_scene.gnngarment(
            filepath=case["manifest"], use_point_cache=case["use_point_cache"],
            include_body=case["include_body"])
        results["cases"][label] = {"outcome": sorted(outcome), **describe_scene()}
    for label, manifest in config["bad"].items():
        fresh_scene()
        try:
            outcome, message = sorted(bpy.ops.import_scene.gnngarment(filepath=manifest)), ""
        except RuntimeError as error:  # an operator's ERROR report raises in bpy
            outcome, message = ["ERROR"], str(error)
        scene = bpy.context.scene
        results["bad"][label] = {"outcome": outcome, "message": message,
                                 "fps": scene.render.fps, "objects": len(scene.objects)}
    # The pitfall the add-on fixes: the glb with the glTF importer alone, 24 fps scene.
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=config["plain_glb"])
    results["plain_gltf"] = {
        "fps": bpy.context.scene.render.fps,
        "actions": sorted(frame_range(a) for a in bpy.data.actions)}
    with open(result_path, "w") as stream:
        json.dump(results, stream)


if __name__ == "__main__":
    main(*sys.argv[1:3])
