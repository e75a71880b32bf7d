#!/usr/bin/env python3
"""Writes scenes/instances.yaml: a field of 100,000 instanced torus knots (DESIGN.md §11).

Eight groups hold the 38,400-triangle knot of scenes/meshes/torus_knot.obj, each turned its own
way and in its own material; 316 x 317 instances (100,172... cut to exactly 100,000) place them on
a jittered grid. The field is deterministic (a fixed linear congruential generator), so running
this again writes the same bytes.  usage: scripts/make-instances-scene.py [OUT]
"""
import sys
from pathlib import Path

COUNT = 100_000
SIDE = 317  # instances per row
SPACING = 0.6
GROUPS = 8

root = Path(__file__).resolve().parent.parent
out = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "scenes" / "instances.yaml"

state = 12345


def uniform():
    global state
    state = (state * 6364136223846793005 + 1442695040888963407) % 2**64
    return (state >> 11) / 2**53


colours = [
    (0.80, 0.32, 0.12), (0.85, 0.66, 0.20), (0.25, 0.55, 0.80), (0.70, 0.20, 0.35),
    (0.30, 0.70, 0.45), (0.55, 0.40, 0.80), (0.90, 0.85, 0.78), (0.20, 0.35, 0.55),
]
lines = [
    "# A field of 100,000 instanced meshes (DESIGN.md §11): eight groups, each the 38,400-triangle",
    "# torus knot of meshes/torus_knot.obj turned its own way in its own material, placed 100,000",
    "# times by `type: instance` (3.8 billion triangles; each group's BVH is built once and shared).",
    "# Written by scripts/make-instances-scene.py; edit that, not this file.",
    "name: instances",
    "background: [0.55, 0.68, 0.85]",
    "ambient: { color: [0.8, 0.85, 1], intensity: 0.15 }",
    "camera: { position: [0.4, 1.5, 6], look_at: [0, 0.2, -12], fov: 40 }",
    "image: { width: 800, height: 450, samples: 4 }",
    "render: { max_depth: 3 }",
    "materials:",
    "  ground: { kd: [0.35, 0.33, 0.3], ks: 0.1, shininess: 20 }",
]
for g, (r, gr, b) in enumerate(colours):
    lines.append(f"  m{g}: {{ kd: [{r}, {gr}, {b}], ks: 0.5, shininess: 60 }}")
lines.append("groups:")
for g in range(GROUPS):
    tilt = 90 + 25 * (g % 3)
    turn = 45 * g
    lines.append(
        f"  k{g}: [{{ type: mesh, file: meshes/torus_knot.obj, material: m{g}, transform: "
        f"[{{scale: 0.075}}, {{rotate: {{axis: [1, 0, 0], angle: {tilt}}}}}, "
        f"{{rotate: {{axis: [0, 1, 0], angle: {turn}}}}}, {{translate: [0, 0.27, 0]}}] }}]")
lines += [
    "lights:",
    "  - { type: directional, direction: [-0.5, -1, -0.7], color: [1, 0.95, 0.85], intensity: 0.9 }",
    "objects:",
    "  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: ground }",
]
for i in range(COUNT):
    row, col = divmod(i, SIDE)
    x = (col - (SIDE - 1) / 2) * SPACING + (uniform() - 0.5) * 0.25
    z = 4 - row * SPACING + (uniform() - 0.5) * 0.25
    g = int(uniform() * GROUPS)
    lines.append(f"  - {{type: instance, group: k{g}, transform: [{{translate: [{x:.3f}, 0, {z:.3f}]}}]}}")
out.write_text("\n".join(lines) + "\n")
print(f"wrote {out}")
