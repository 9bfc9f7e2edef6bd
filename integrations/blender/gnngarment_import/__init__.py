"""Blender add-on: *File → Import → gnngarment export (_export.json)*.

Opens the folder ``gnngarment animate GARMENT --out DIR`` wrote, by its manifest
(``<name>_export.json``, or ``outfit_export.json`` for an outfit), in one step:

1. sets the scene's frame rate (``render.fps`` / ``fps_base``) to the manifest's ``fps``
   and its frame range to ``first_frame … first_frame + frames − 1``, *before* importing
   (Blender's glTF importer turns key times into frames with the scene's rate at import
   time, so a 30 fps glb in the default 24 fps scene would be keyed between frames);
2. imports the ``.glb`` (armature, one skinned + shape-key-animated mesh per garment,
   the body) — or, with *Point Cache*, each garment's rest OBJ with a Mesh Cache
   modifier playing its ``.pc2``;
3. names the objects after the garments (``<name>_body`` for the body) and puts them in
   a collection named after the export.

Install: zip this folder (``python integrations/blender/build_zip.py``) and pick the zip
in *Edit → Preferences → Add-ons → Install from Disk*. See ``docs/export.md``, "Blender".
The bpy-free parts (manifest validation, frame and rate arithmetic) are in
``manifest.py``.
"""

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from .manifest import (
    ExportManifest,
    ManifestError,
    base_name,
    blender_fps,
    importer_fps_base,
    load_manifest,
    read_pc2_header,
)

bl_info = {
    "name": "gnngarment export importer",
    "author": "gnngarment",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "File > Import > gnngarment export (_export.json)",
    "description": "Import an animated garment or outfit exported by gnngarment at its "
                   "frame rate and frame range (glb rig, or rest OBJ + PC2 point cache)",
    "category": "Import-Export",
}

#: The collection Blender's glTF importer keeps its bone-shape helper in.
GLTF_HELPERS = "glTF_not_exported"


class GnngarmentImportError(RuntimeError):
    """An import step failed; the message is for the user."""


def apply_scene_timing(scene: bpy.types.Scene, manifest: ExportManifest) -> None:
    """Frame rate and frame range of the export: frame ``first_frame + k`` shows pose
    ``k`` in every format."""
    fps, fps_base = blender_fps(manifest.fps)
    scene.render.fps, scene.render.fps_base = fps, fps_base
    start, end = manifest.frame_range
    # Blender keeps start ≤ end by moving the other: set them in an order that never
    # crosses the old range.
    if start > scene.frame_end:
        scene.frame_end, scene.frame_start = end, start
    else:
        scene.frame_start, scene.frame_end = start, end
    scene.frame_current = start


def _new_objects(before: set) -> list[bpy.types.Object]:
    return [obj for obj in bpy.data.objects if obj not in before]


def _is_helper(obj: bpy.types.Object) -> bool:
    return any(collection.name.startswith(GLTF_HELPERS) for collection in obj.users_collection)


def _remove_object(obj: bpy.types.Object) -> None:
    data = obj.data
    bpy.data.objects.remove(obj)
    if isinstance(data, bpy.types.Mesh) and data.users == 0:
        bpy.data.meshes.remove(data)


def _rename(obj: bpy.types.Object, name: str, warnings: list[str]) -> None:
    obj.name = name
    if obj.name != name:
        warnings.append(f"an object named {name!r} already exists: imported as {obj.name!r}")


def import_glb(context, manifest: ExportManifest, include_body: bool,
               warnings: list[str]) -> list[bpy.types.Object]:
    """The export's glb; returns the objects kept (armature, garments, body)."""
    scene = context.scene
    before = set(bpy.data.objects)
    fps_base = scene.render.fps_base
    # The importer keys time t at frame t · fps · fps_base (it should divide).
    scene.render.fps_base = importer_fps_base(fps_base)
    try:
        result = bpy.ops.import_scene.gltf(filepath=str(manifest.glb))
    except RuntimeError as error:
        raise GnngarmentImportError(f"{manifest.files['glb']}: the glTF importer failed: "
                           f"{error}") from None
    finally:
        scene.render.fps_base = fps_base
    if "FINISHED" not in result:
        raise GnngarmentImportError(f"{manifest.files['glb']}: the glTF importer did not finish")
    new = [obj for obj in _new_objects(before) if not _is_helper(obj)]
    kept = [obj for obj in new if obj.type == "ARMATURE"]
    for garment in manifest.garments:
        meshes = [obj for obj in new if obj.type == "MESH" and base_name(obj.name) == garment]
        # A skinned node with a weights (morph) track stays behind as an empty and the
        # importer puts its mesh on a new child of the armature ("skirt" + "skirt.001").
        for obj in [obj for obj in new if obj.type == "EMPTY"
                    and base_name(obj.name) == garment and not obj.children
                    and not (obj.animation_data and obj.animation_data.action)]:
            new.remove(obj)
            _remove_object(obj)
        if len(meshes) != 1:
            raise GnngarmentImportError(f"{manifest.files['glb']}: expected one mesh named "
                               f"{garment!r}, found {len(meshes)}")
        _rename(meshes[0], garment, warnings)
        meshes[0].data.name = garment
        kept.append(meshes[0])
    for obj in [obj for obj in new if obj.type == "MESH" and base_name(obj.name) == "body"
                and obj not in kept]:
        if include_body:
            _rename(obj, manifest.body_name, warnings)
            kept.append(obj)
        else:
            _remove_object(obj)
    return kept


def import_point_caches(context, manifest: ExportManifest, include_body: bool,
                        warnings: list[str]) -> list[bpy.types.Object]:
    """Each rest OBJ with a Mesh Cache modifier playing its ``.pc2``."""
    meshes = manifest.point_caches(include_body)
    headers = {}
    for mesh in meshes:  # every file checked before anything is imported
        points, start, _rate, samples = headers[mesh.name] = read_pc2_header(mesh.pc2)
        if samples != manifest.frames:
            raise GnngarmentImportError(f"{mesh.pc2.name}: {samples} samples, the manifest says "
                               f"{manifest.frames} frames")
        if start != manifest.first_frame:
            warnings.append(f"{mesh.pc2.name}: header start frame {start:g}, the manifest "
                            f"says {manifest.first_frame} (the modifier follows the manifest)")
    kept: list[bpy.types.Object] = []
    try:
        for mesh in meshes:
            before = set(bpy.data.objects)
            # The OBJs are Z up, the body facing −Y: no axis conversion.
            bpy.ops.wm.obj_import(filepath=str(mesh.obj), forward_axis="Y", up_axis="Z")
            new = _new_objects(before)
            kept += new
            if len(new) != 1 or new[0].type != "MESH":
                raise GnngarmentImportError(f"{mesh.obj.name}: expected one mesh, the OBJ importer "
                                   f"made {len(new)} objects")
            obj = new[0]
            points = headers[mesh.name][0]
            if len(obj.data.vertices) != points:
                raise GnngarmentImportError(f"{mesh.obj.name}: {len(obj.data.vertices)} vertices, "
                                   f"{mesh.pc2.name} has {points}")
            _rename(obj, mesh.name, warnings)
            obj.data.name = mesh.name
            if not mesh.is_body:
                obj.data.shade_smooth()  # as the glb's garment normals
            cache = obj.modifiers.new("gnngarment point cache", "MESH_CACHE")
            cache.cache_format = "PC2"
            cache.filepath = str(mesh.pc2)
            cache.time_mode, cache.play_mode = "FRAME", "SCENE"
            # Frame mode shows sample scene_frame · frame_scale − frame_start.
            cache.frame_start, cache.frame_scale = float(manifest.first_frame), 1.0
            cache.forward_axis, cache.up_axis = "POS_Y", "POS_Z"
    except (GnngarmentImportError, RuntimeError):
        for obj in kept:
            _remove_object(obj)
        raise
    return kept


def collect(context, name: str, objects: list[bpy.types.Object]) -> bpy.types.Collection:
    """Move ``objects`` into a new collection ``name`` under the scene's."""
    collection = bpy.data.collections.new(name)
    context.scene.collection.children.link(collection)
    for obj in objects:
        for old in list(obj.users_collection):
            old.objects.unlink(obj)
        collection.objects.link(obj)
    return collection


def import_export(context, filepath: str, use_point_cache: bool = False,
                  include_body: bool = True) -> tuple[list[bpy.types.Object], list[str]]:
    """The whole import (what the operator runs): ``(objects, warnings)``.

    Raises:
        ManifestError: a bad manifest or a missing file (nothing changed).
        GnngarmentImportError: an importer failed.
    """
    manifest = load_manifest(filepath)
    # Check the files first, so a broken export changes nothing in the scene.
    if use_point_cache:
        manifest.point_caches(include_body)
    else:
        _ = manifest.glb
    apply_scene_timing(context.scene, manifest)
    warnings: list[str] = []
    if use_point_cache:
        objects = import_point_caches(context, manifest, include_body, warnings)
    else:
        objects = import_glb(context, manifest, include_body, warnings)
    collect(context, manifest.name, objects)
    for obj in context.view_layer.objects:
        obj.select_set(obj in objects)
    garments = [obj for obj in objects if obj.name in manifest.garments]
    if garments:
        context.view_layer.objects.active = garments[0]
    return objects, warnings


class IMPORT_SCENE_OT_gnngarment(bpy.types.Operator, ImportHelper):  # noqa: N801 (Blender's naming)
    """Import a gnngarment export (its *_export.json) at its frame rate and frame range"""

    bl_idname = "import_scene.gnngarment"
    bl_label = "Import gnngarment export"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a set)

    filename_ext = ".json"
    filter_glob: StringProperty(default="*_export.json", options={"HIDDEN"})
    use_point_cache: BoolProperty(
        name="Point Cache (PC2)",
        description="Import each garment's rest OBJ with a Mesh Cache modifier playing its "
                    ".pc2, instead of the glb's armature and shape keys",
        default=False)
    include_body: BoolProperty(
        name="Body", description="Also import the animated body", default=True)

    def invoke(self, context, event):
        return self.invoke_popup(context)  # the file browser, or a dialog on a drop

    def execute(self, context):
        try:
            objects, warnings = import_export(context, self.filepath, self.use_point_cache,
                                              self.include_body)
        except (ManifestError, GnngarmentImportError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        for warning in warnings:
            self.report({"WARNING"}, warning)
        scene = context.scene
        self.report({"INFO"}, f"gnngarment: {len(objects)} objects at "
                              f"{scene.render.fps / scene.render.fps_base:g} fps, frames "
                              f"{scene.frame_start}–{scene.frame_end}")
        return {"FINISHED"}


class IO_FH_gnngarment(bpy.types.FileHandler):  # noqa: N801 (Blender's naming)
    """Drag and drop a *_export.json onto the viewport."""

    bl_idname = "IO_FH_gnngarment"
    bl_label = "gnngarment export"
    bl_import_operator = "import_scene.gnngarment"
    bl_file_extensions = ".json"

    @classmethod
    def poll_drop(cls, context):
        area = context.area
        return area is not None and area.type in {"VIEW_3D", "OUTLINER"}


def menu_import(self, context):
    self.layout.operator(IMPORT_SCENE_OT_gnngarment.bl_idname,
                         text="gnngarment export (_export.json)")


CLASSES = (IMPORT_SCENE_OT_gnngarment, IO_FH_gnngarment)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
