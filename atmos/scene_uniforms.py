"""The camera's and the sun's uniforms of a program that declares them itself, from the scene's
data (:class:`atmos.Camera`, :class:`atmos.Sun`, :class:`atmos.SceneView`) through the one uniform
writer. A program that includes ``lib/frame.glsl`` reads them from the frame block instead
(:mod:`atmos.frame_constants`): the writers here do nothing for it."""
from __future__ import annotations

from atmos.camera import Camera, camera_matrices
from atmos.frame_constants import FRAME_BLOCK
from atmos.gpu.uniforms import has_member, write_uniforms
from atmos.lighting import Sun

MATRICES = ("view_proj", "inv_view_proj", "view_basis")   # computed on first use per frame (CameraMatrices.gl)


def set_camera_uniforms(program, camera: Camera, aspect: float) -> None:
    """Write the camera uniforms ``program`` has (the compiler drops unused ones): ``view_proj``,
    ``inv_view_proj``, ``view_basis`` (:func:`atmos.camera.view_basis`), ``camera_pos``, ``near``, ``far``.

    ``view_basis``, ``camera_pos``, ``near`` and ``far`` are what ``lib/view_ray.glsl`` needs for
    view rays and distances from depth at any far/near ratio; prefer them to ``inv_view_proj``.
    The matrices come from :func:`atmos.camera.camera_matrices`: computed once per frame, whatever the passes.
    Nothing for a program with the frame block (``lib/frame.glsl``)."""
    if has_member(program, FRAME_BLOCK):
        return
    matrices = camera_matrices(camera, aspect)
    write_uniforms(program, {name: matrices.gl(name) for name in MATRICES if has_member(program, name)},
                   camera_pos=matrices.camera_pos, near=float(camera.near), far=float(camera.far))


def set_sun_uniforms(program, sun: Sun) -> None:
    """Write ``sun_dir``, ``sun_color`` and ``sky_ambient`` (the Sun's ambient) where the program has them
    (nothing for a program with the frame block)."""
    if has_member(program, FRAME_BLOCK):
        return
    write_uniforms(program, **{name: tuple(float(v) for v in value) for name, value in
                               (("sun_dir", sun.direction), ("sun_color", sun.color), ("sky_ambient", sun.ambient))})


def set_scene_uniforms(program, view) -> None:
    """The camera (:func:`set_camera_uniforms`) and sun (:func:`set_sun_uniforms`) uniforms of a
    :class:`atmos.SceneView`: what a pass drawing the lit scene writes each frame."""
    set_camera_uniforms(program, view.camera, view.aspect)
    set_sun_uniforms(program, view.sun)
