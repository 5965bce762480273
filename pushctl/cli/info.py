"""``pushctl info``: the model of an object and an arm, as tables."""

from __future__ import annotations

from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from pushctl.cli.common import (
    OBJECT_HELP,
    Command,
    console,
    fail,
)
from pushctl.errors import PushctlError

app = typer.Typer()


@app.command(cls=Command)
def info(
    object_name: Annotated[str, typer.Option("--object", help=OBJECT_HELP)] = "cube",
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
) -> None:
    """Show the model of an object and an arm: mass properties, supports, ready pose."""
    from pushctl import native
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.config import PusherConfig
    from pushctl.objects import resolve_object

    try:
        spec = resolve_object(object_name)
        model = load_arm(ArmConfig(name=arm, pusher=PusherConfig(mass=spec.pusher_mass)))
    except PushctlError as error:
        fail(error)
    table = Table(title=f"object {spec.name!r}", show_header=False)
    table.add_row("mass", f"{spec.mass:.4g} kg")
    table.add_row("I_z about the centre of mass", f"{spec.inertia_z:.4e} kg·m²")
    table.add_row("centre of mass height", f"{1e3 * spec.com_height:.2f} mm")
    table.add_row("centre of mass to pushed face", f"{1e3 * spec.face_offset:.2f} mm")
    for point, load in zip(np.asarray(spec.support_points), spec.support_loads, strict=True):
        table.add_row(
            "support point (x, y) / load",
            f"({1e3 * point[0] + 0.0:.1f}, {1e3 * point[1] + 0.0:.1f}) mm / {load:.4f} N",
        )
    table.add_row("pusher mass (Table II)", f"{spec.pusher_mass:.3g} kg")
    console.print(table)
    arm_table = Table(title=f"arm {model.name!r}", show_header=False)
    arm_table.add_row("joints (nq, nv)", f"{model.nq}, {model.nv}")
    arm_table.add_row("armature", ", ".join(f"{a:.4g}" for a in model.armature) + " kg·m²")
    arm_table.add_row("damping", ", ".join(f"{d:.4g}" for d in model.damping) + " N·m·s/rad")
    arm_table.add_row("ready q", ", ".join(f"{q:.4f}" for q in model.q_ready) + " rad")
    position = ", ".join(f"{x:.3f}" for x in model.ready_pusher_position)
    arm_table.add_row("ready pusher position", f"({position}) m")
    jacobian = model.pusher_jacobian(model.q_ready)
    mass = model.compute(model.q_ready, np.zeros(model.nv)).M
    arm_table.add_row("cond J (pusher, ready)", f"{np.linalg.cond(jacobian):.1f}")
    arm_table.add_row(
        "smallest eigenvalue of M (ready)", f"{np.linalg.eigvalsh(mass)[0]:.4f} kg·m²"
    )
    arm_table.add_row("arm terms computed by", native.status())
    console.print(arm_table)
