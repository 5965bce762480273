"""The pusher plate as a rigid body on the end-effector link, and its Pinocchio frames.

Geometry (PusherConfig: ``width`` along the face, ``height`` vertical, ``thickness`` along
the push direction). With the tool pointing down, the plate hangs below the end-effector
frame: its top edge is at the end-effector origin, so its centre lies ``height/2`` along
the tool axis; its front face is ``thickness/2`` ahead of the end-effector origin along the
push direction.

The ``pusher`` frame has its origin at the centre of the front face at mid-height (the
prongs' midpoint), x = push direction (out of the front face), z = up in the ready pose
(minus the tool axis), y = z × x along the face. Prong i sits at (0, t_i, 0) in it, with
t_i = ``PusherConfig.prong_offsets()[i]``. A mounting error (``PusherConfig.mount_yaw``,
``prong_errors``) turns the plate about the tool axis through the end-effector origin and
moves the prongs to ``PusherConfig.prong_points()``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pushctl.config import PusherConfig

PUSHER_FRAME = "pusher"
"""Name of the pusher frame in the Pinocchio model."""

NOMINAL_PUSHER_FRAME = "pusher_nominal"
"""Name of the frame where the pusher would be without its mounting yaw (the controller's
belief), added to the model of an arm whose plate has one."""


def prong_frame_name(i: int) -> str:
    """Name of prong ``i``'s frame (0-based, ascending t_i)."""
    return f"pusher_prong_{i}"


def rotation_ee_to_pusher(push_axis_ee, tool_axis_ee) -> np.ndarray:
    """Pusher axes in the end-effector frame, (3, 3) columns x, y, z: an exact permutation
    with signs when the two given axes are unit coordinate axes."""
    x_axis = np.asarray(push_axis_ee, dtype=float)
    z_axis = -np.asarray(tool_axis_ee, dtype=float)
    return np.column_stack([x_axis, np.cross(z_axis, x_axis), z_axis])


def placement_ee_to_pusher(push_axis_ee, tool_axis_ee, pusher: PusherConfig) -> pin.SE3:
    """Placement of the pusher frame in the end-effector frame (``eeMp``), turned by the
    plate's ``mount_yaw`` about the tool axis (up in the pusher frame)."""
    translation = 0.5 * pusher.thickness * np.asarray(push_axis_ee, dtype=float)
    translation += 0.5 * pusher.height * np.asarray(tool_axis_ee, dtype=float)
    placement = pin.SE3(rotation_ee_to_pusher(push_axis_ee, tool_axis_ee), translation)
    if pusher.mount_yaw == 0.0:
        return placement
    up = -np.asarray(tool_axis_ee, dtype=float)
    mount = pin.SE3(pin.AngleAxis(pusher.mount_yaw, up).matrix(), np.zeros(3))
    return mount * placement


def plate_inertia(pusher: PusherConfig) -> pin.Inertia:
    """Spatial inertia of the uniform plate, expressed in the pusher frame.

    The plate's centre is ``thickness/2`` behind the front face: (−thickness/2, 0, 0) [m].
    """
    m, t, w, h = pusher.mass, pusher.thickness, pusher.width, pusher.height
    inertia_com = (m / 12.0) * np.diag([w * w + h * h, t * t + h * h, t * t + w * w])
    return pin.Inertia(m, np.array([-0.5 * t, 0.0, 0.0]), inertia_com)


def attach_pusher(
    model: pin.Model, ee_frame: str, eeMp: pin.SE3, pusher: PusherConfig
) -> tuple[int, tuple[int, ...]]:
    """Append the plate's inertia to the end-effector's joint and add the pusher frames.

    Modifies ``model`` in place. Returns ``(pusher_frame_id, prong_frame_ids)``.
    """
    ee_id = model.getFrameId(ee_frame)
    ee = model.frames[ee_id]
    jMp = ee.placement * eeMp  # pusher frame in the parent joint's frame (as add_frame_on_ee)
    model.appendBodyToJoint(ee.parentJoint, plate_inertia(pusher), jMp)
    pusher_id = model.addFrame(
        pin.Frame(PUSHER_FRAME, ee.parentJoint, ee_id, jMp, pin.FrameType.OP_FRAME), False
    )
    prong_ids = []
    for i, (along, across) in enumerate(pusher.prong_points()):
        jMprong = jMp * pin.SE3(np.eye(3), np.array([float(along), float(across), 0.0]))
        frame = pin.Frame(
            prong_frame_name(i), ee.parentJoint, pusher_id, jMprong, pin.FrameType.OP_FRAME
        )
        prong_ids.append(model.addFrame(frame, False))
    return pusher_id, tuple(prong_ids)


def add_frame_on_ee(model: pin.Model, ee_frame: str, eeMf: pin.SE3, name: str) -> int:
    """Add a massless frame ``name`` at ``eeMf`` in the end-effector frame (its placement in
    the parent joint's frame computed as :func:`attach_pusher` computes the pusher's, so the
    same ``eeMf`` gives the same bits). Modifies ``model`` in place; returns the frame id."""
    ee_id = model.getFrameId(ee_frame)
    ee = model.frames[ee_id]
    jMf = ee.placement * eeMf
    return model.addFrame(
        pin.Frame(name, ee.parentJoint, ee_id, jMf, pin.FrameType.OP_FRAME), False
    )
