"""File formats: the one home of every reader and writer of bytes on disk.

Modules (import the one you need; this package imports nothing, so ``import
gnngarment.io.<module>`` loads only numpy and that module):

- :mod:`~gnngarment.io.atomic`: :func:`~gnngarment.io.atomic.atomic_write` (temp file,
  fsync, rename) and :class:`~gnngarment.io.atomic.FolderLock` (one run per output folder)
- :mod:`~gnngarment.io.npz`: :func:`~gnngarment.io.npz.save_npz_atomic`,
  :func:`~gnngarment.io.npz.load_npz` (errors name the file)
- :mod:`~gnngarment.io.point_cache`: PointCache2 ``.pc2`` (float32) / ``.pc16`` (float16)
- :mod:`~gnngarment.io.mat`: MATLAB v5 ``.mat`` (CLOTH3D's ``info.mat``) as plain Python
- :mod:`~gnngarment.io.obj`: Wavefront OBJ text (:func:`~gnngarment.io.obj.write_obj`,
  :func:`~gnngarment.io.obj.obj_text`); reading OBJ is
  :func:`gnngarment.geometry.load_mesh`'s job

Nothing here imports anything else of ours, so every package (``geometry`` included)
may use it.
"""
