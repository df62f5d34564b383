"""Small, exactly known toolpaths for tests, golden files, benchmarks and demos."""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.toolpath import Toolpath, ToolpathBuilder


def tilted_ring(radius: float = 8.0, height: float = 5.0, tilt_deg: float = 30.0,
                points: int = 24) -> Toolpath:
    """Travel in, cure a ring with the tool tilted outward, dwell, deposit a straight bead."""
    t = np.linspace(0.0, 2.0 * math.pi, points)
    tilt = math.radians(tilt_deg)
    ring = np.stack([radius * np.cos(t), radius * np.sin(t), np.full_like(t, height)], axis=1)
    normals = np.stack([math.sin(tilt) * np.cos(t), math.sin(tilt) * np.sin(t),
                        np.full_like(t, math.cos(tilt))], axis=1)
    builder = ToolpathBuilder(part="tilted ring", material="UV resin")
    builder.event("tool_change", tool=1)
    builder.add_segment([[radius, 0.0, height + 20.0], ring[0]], axes=[[0, 0, 1], normals[0]],
                        kind="travel", feed=3000.0, tool=1)
    builder.event("light_on", power=0.75)
    builder.add_segment(ring, normals, kind="cure", feed=45.0, tool=1, flow=0.02)
    builder.event("light_off")
    builder.event("dwell", seconds=0.5)
    builder.event("extruder_on")
    builder.add_segment([[radius, 0.0, height], [radius, 10.0, height], [radius, 20.0, height]],
                        axes=(0, 0, 1), kind="deposit", feed=600.0, tool=1, flow=0.1)
    builder.event("extruder_off")
    return builder.build()


def flat_square(side: float = 20.0, z: float = 0.3) -> Toolpath:
    """A 3-axis deposit square with a travel in, for the plain machine."""
    square = np.array([[0, 0], [side, 0], [side, side], [0, side], [0, 0]], dtype=float) + 50.0
    layer = np.column_stack([square, np.full(len(square), z)])
    builder = ToolpathBuilder(part="flat square", material="PLA")
    builder.add_segment([[50.0, 50.0, z + 10.0], layer[0]], kind="travel", feed=6000.0)
    builder.event("extruder_on")
    builder.add_segment(layer, kind="deposit", feed=1200.0, flow=0.08)
    builder.event("extruder_off")
    return builder.build()


def mandrel_helix(turns: float = 10.0, radius: float = 20.0, pitch: float = 2.0,
                  chord_tolerance: float = 0.01, interpolation: str = "joint_linear",
                  x0: float = 5.0) -> Toolpath:
    """A helix on a mandrel about X, sampled as a planner would at `chord_tolerance`.

    Unrolled it is one straight line, so on a rotary-mandrel machine it is one block.
    """
    step = 2.0 * math.acos(1.0 - chord_tolerance / radius)       # chord sagitta = tolerance
    count = int(math.ceil(turns * 2.0 * math.pi / step)) + 1
    t = np.linspace(0.0, turns * 2.0 * math.pi, count)
    points = np.stack([x0 + pitch * t / (2.0 * math.pi), radius * np.sin(t), radius * np.cos(t)], axis=1)
    axes = np.stack([np.zeros_like(t), np.sin(t), np.cos(t)], axis=1)
    builder = ToolpathBuilder(part=f"{turns:g}-turn helix", material="PLA")
    builder.add_segment([points[0] + axes[0] * 5.0, points[0]], axes=axes[0], kind="travel",
                        feed=2400.0)
    builder.add_segment(points, axes, kind="deposit", feed=2000.0, flow=0.12,
                        interpolation=interpolation)
    return builder.build()


def dome_spiral(points: int, radius: float = 30.0, turns: float = 40.0,
                max_tilt_deg: float = 60.0, segments: int = 100,
                center: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Toolpath:
    """A spiral on a sphere cap with the tool along the surface normal (5-axis cure).

    Centred on an A/C table's pivot the joints move linearly (one block per segment);
    off the pivot X, Y, Z swing with the table and the post must subdivide.
    """
    u = np.linspace(0.0, 1.0, points)
    polar = np.radians(max_tilt_deg) * (0.05 + 0.95 * u)
    azimuth = 2.0 * math.pi * turns * u
    normals = np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth),
                        np.cos(polar)], axis=1)
    builder = ToolpathBuilder(part="dome spiral", material="UV resin")
    for chunk_points, chunk_axes in zip(np.array_split(normals * radius + center, segments),
                                        np.array_split(normals, segments)):
        builder.add_segment(chunk_points, chunk_axes, kind="cure", feed=120.0, tool=1, flow=0.01)
    return builder.build()
