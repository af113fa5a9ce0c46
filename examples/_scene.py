"""The examples' scene: the project's MJCF of an arm on a floor, obstacles, and a mocap target."""

import mujoco

import om_redundant as om


def scene(arm: om.Arm, obstacles: dict[str, dict]) -> mujoco.MjModel:
    """The arm's scene (:func:`om.scene_mjcf`) with obstacle geoms (name -> ``MjSpec`` geom
    fields) and a mocap body ``target`` carrying a green site."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(arm))
    for name, geom in obstacles.items():
        spec.worldbody.add_geom(name=name, rgba=[0.9, 0.4, 0.1, 0.7], **geom)
    target = spec.worldbody.add_body(name="target", mocap=True)
    target.add_site(name="target", size=[0.02, 0, 0], rgba=[0.1, 0.8, 0.1, 0.8])
    return spec.compile()
