#!/usr/bin/env python3
"""Writes the Tachyon (.dat) example scenes of scenes/: small scenes in the form VMD writes them.

  scripts/make-tachyon-scenes.py [FOLDER]     (default: scenes/ beside this script's folder)

vmd-helix.dat: a ball-and-stick "molecule" (a double helix of atoms joined by FCYLINDER bonds, as
VMD's CPK representation writes them, TEXDEF materials with Phong highlights), a translucent
vertex-coloured surface (VERTEXARRAY with COLORS and TRISTRIPs under TRANS_VMD), a RING, an
orthographic camera, directional lights, fog and a plain background — VMD's usual statements.
tachyon-shapes.dat: Tachyon's other statements: a perspective camera with antialiasing, point
lights with attenuation, a spotlight, SPHERE, FCYLINDER, CYLINDER, RING, PLANE, BOX, TRI, STRI,
VCSTRI, TEXALIAS, metal and plastic Phong, a mirror and a transparent texture.
"""
import math
import os
import sys


def helix(out):
    out.append("# Molecular graphics in the form VMD exports for Tachyon (made by")
    out.append("# scripts/make-tachyon-scenes.py)")
    out.append("Begin_Scene")
    out.append("Resolution 640 480")
    out.append("Shader_Mode Full")
    out.append("  Trans_VMD")
    out.append("  Fog_VMD")
    out.append("End_Shader_Mode")
    out.append("# Begin_Camera")
    out.append("Camera")
    out.append("  Projection Orthographic")
    out.append("  Zoom 0.085")
    out.append("  Aspectratio 1")
    out.append("  Antialiasing 3")
    out.append("  Raydepth 8")
    out.append("  Center  0 0 -20")
    out.append("  Viewdir 0 0 1")
    out.append("  Updir   0 1 0")
    out.append("End_Camera")
    out.append("# End_Camera")
    out.append("Directional_Light Direction 0.1 -0.1 1 Color 1 1 1")
    out.append("Directional_Light Direction -1 -2 0.5 Color 0.6 0.6 0.6")
    out.append("")
    out.append("Background 0.95 0.95 0.98")
    out.append("Fog Exp2 Start 0 End 60 Density 0.02")
    out.append("  Color 0.95 0.95 0.98")
    colors = {"C": (0.25, 0.75, 0.75), "O": (1, 0.1, 0.1), "N": (0.1, 0.2, 1), "P": (0.8, 0.6, 0.1)}
    for i, (name, rgb) in enumerate(colors.items()):
        out.append(f"Texdef txt{i:03d}")
        out.append("  Ambient 0 Diffuse 0.65 Specular 0 Opacity 1")
        out.append(f"Phong Plastic 0.5 Phong_size 40 Color {rgb[0]} {rgb[1]} {rgb[2]} TexFunc 0")
    out.append("Texdef bond")
    out.append("  Ambient 0 Diffuse 0.65 Specular 0 Opacity 1")
    out.append("Phong Plastic 0.5 Phong_size 40 Color 0.7 0.7 0.7 TexFunc 0")
    names = list(colors)
    atoms = []
    for strand in range(2):
        for k in range(16):
            a = k * 0.6 + strand * math.pi
            p = (2.2 * math.cos(a), k * 0.55 - 4.4, 2.2 * math.sin(a))
            atoms.append((p, names[(k + strand) % 4]))
    for i, (p, element) in enumerate(atoms):
        out.append(f"Sphere Center {p[0]:.4f} {p[1]:.4f} {p[2]:.4f} Rad 0.45 "
                   f"txt{names.index(element):03d}")
    for strand in range(2):
        for k in range(15):
            a = atoms[strand * 16 + k][0]
            b = atoms[strand * 16 + k + 1][0]
            out.append(f"FCylinder Base {a[0]:.4f} {a[1]:.4f} {a[2]:.4f} "
                       f"Apex {b[0]:.4f} {b[1]:.4f} {b[2]:.4f} Rad 0.15 bond")
    for k in range(0, 16, 3):
        a = atoms[k][0]
        b = atoms[16 + k][0]
        out.append(f"FCylinder Base {a[0]:.4f} {a[1]:.4f} {a[2]:.4f} "
                   f"Apex {b[0]:.4f} {b[1]:.4f} {b[2]:.4f} Rad 0.1 bond")
    # A translucent coloured tube around the helix: a vertex array of triangle strips.
    rings, around = 12, 16
    out.append(f"VertexArray  Numverts {rings * around}")
    coords, normals, cols = [], [], []
    for j in range(rings):
        y = j * 0.8 - 4.4
        for i in range(around):
            a = 2 * math.pi * i / around
            n = (math.cos(a), 0, math.sin(a))
            coords.append(f"{3.4 * n[0]:.4f} {y:.4f} {3.4 * n[2]:.4f}")
            normals.append(f"{n[0]:.4f} 0 {n[2]:.4f}")
            t = j / (rings - 1)
            cols.append(f"{t:.3f} {0.4 + 0.4 * math.sin(a) ** 2:.3f} {1 - t:.3f}")
    out.append("Coords")
    out.extend(coords)
    out.append("Normals")
    out.extend(normals)
    out.append("Colors")
    out.extend(cols)
    out.append("Texture")
    out.append("  Ambient 0.1 Diffuse 0.6 Specular 0 Opacity 0.35")
    out.append("Phong Plastic 0.3 Phong_size 30 Color 1 1 1 TexFunc 0")
    for j in range(rings - 1):
        strip = []
        for i in range(around + 1):
            strip += [j * around + i % around, (j + 1) * around + i % around]
        out.append(f"TriStrip {len(strip)} " + " ".join(map(str, strip)))
    out.append("End_VertexArray")
    out.append("Ring Center 0 -5.2 0 Normal 0 1 0 Inner 2 Outer 4.2 bond")
    out.append("End_Scene")


def shapes(out):
    out.append("# Tachyon's other statements (made by scripts/make-tachyon-scenes.py)")
    out.append("BEGIN_SCENE")
    out.append("  RESOLUTION 640 400")
    out.append("CAMERA")
    out.append("  ZOOM 0.9")
    out.append("  ASPECTRATIO 1.0")
    out.append("  ANTIALIASING 4")
    out.append("  RAYDEPTH 6")
    out.append("  CENTER 0.0 3.0 -11.0")
    out.append("  VIEWDIR 0.0 -0.3 1.0")
    out.append("  UPDIR 0.0 1.0 0.0")
    out.append("END_CAMERA")
    out.append("BACKGROUND 0.05 0.07 0.12")
    out.append("LIGHT CENTER -6 9 -8 RAD 0.0 ATTENUATION CONSTANT 0.6 LINEAR 0.02 QUADRATIC 0.0 "
               "COLOR 0.9 0.9 0.85")
    out.append("LIGHT CENTER 6 4 -6 RAD 0.0 COLOR 0.3 0.3 0.4")
    out.append("SPOTLIGHT CENTER 2 8 2 RAD 0.0 DIRECTION -0.2 -1 0 FALLOFF_START 15.0 "
               "FALLOFF_END 30.0 COLOR 1.0 0.8 0.5")
    out.append("TEXDEF floor AMBIENT 0.1 DIFFUSE 0.7 SPECULAR 0.2 OPACITY 1.0 "
               "COLOR 0.6 0.6 0.65 TEXFUNC 0")
    out.append("TEXDEF gold AMBIENT 0.1 DIFFUSE 0.5 SPECULAR 0.3 OPACITY 1.0 "
               "PHONG METAL 0.6 PHONG_SIZE 60 COLOR 1.0 0.75 0.3 TEXFUNC 0")
    out.append("TEXDEF red AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0.0 OPACITY 1.0 "
               "PHONG PLASTIC 0.4 PHONG_SIZE 30 COLOR 0.9 0.15 0.1 TEXFUNC 0")
    out.append("TEXDEF glass AMBIENT 0.0 DIFFUSE 0.1 SPECULAR 0.2 OPACITY 0.3 "
               "PHONG PLASTIC 0.8 PHONG_SIZE 100 COLOR 0.8 0.9 1.0 TEXFUNC 0")
    out.append("TEXALIAS ruby red")
    out.append("PLANE CENTER 0 -1 0 NORMAL 0 1 0 floor")
    out.append("SPHERE CENTER -3 0.5 2 RAD 1.5 gold")
    out.append("SPHERE CENTER 0.5 0 -1 RAD 1.0 glass")
    out.append("FCYLINDER BASE 3 -1 3 APEX 3 2 3 RAD 0.7 ruby")
    out.append("CYLINDER CENTER 7 0 9 AXIS 0 1 0 RAD 0.6 red")
    out.append("RING CENTER 3 2.05 3 NORMAL 0 1 0 INNER 0.3 OUTER 0.7 gold")
    out.append("BOX MIN -1 -1 3 MAX 1 0.5 4.5 red")
    out.append("TRI V0 -6 -1 6 V1 -4 -1 7 V2 -5 2 6.5 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 "
               "SPECULAR 0 OPACITY 1 COLOR 0.2 0.8 0.3 TEXFUNC 0")
    # A smooth dome of STRIs, and a VCSTRI fan of colours.
    for i in range(12):
        a0, a1 = 2 * math.pi * i / 12, 2 * math.pi * (i + 1) / 12
        for ring in range(3):
            e0, e1 = ring * math.pi / 6, (ring + 1) * math.pi / 6

            def p(a, e):
                return (5 + 1.2 * math.cos(e) * math.cos(a), -1 + 1.2 * math.sin(e),
                        -2 + 1.2 * math.cos(e) * math.sin(a))

            def n(a, e):
                return (math.cos(e) * math.cos(a), math.sin(e), math.cos(e) * math.sin(a))

            # Wound counterclockwise seen from outside, as their normals point (Tachyon turns a
            # smooth triangle's normals to the side its winding faces the viewer from).
            for tri in ((p(a0, e0), p(a1, e1), p(a1, e0), n(a0, e0), n(a1, e1), n(a1, e0)),
                        (p(a0, e0), p(a0, e1), p(a1, e1), n(a0, e0), n(a0, e1), n(a1, e1))):
                written = [f"{v[0]:.4f} {v[1]:.4f} {v[2]:.4f}" for v in tri]
                # At the pole two corners meet: no triangle (glint would drop it with a warning).
                if len(set(written[:3])) < 3:
                    continue
                out.append("STRI " + " ".join(
                    f"{k}{j} {v}" for (k, j), v in zip([("V", 0), ("V", 1), ("V", 2), ("N", 0),
                                                        ("N", 1), ("N", 2)], written)) + " gold")
    for i in range(8):
        a0, a1 = 2 * math.pi * i / 8, 2 * math.pi * (i + 1) / 8
        c0 = (0.5 + 0.5 * math.cos(a0), 0.5 + 0.5 * math.sin(a0), 0.5)
        c1 = (0.5 + 0.5 * math.cos(a1), 0.5 + 0.5 * math.sin(a1), 0.5)
        out.append(f"VCSTRI V0 -2 -0.99 -4 V1 {-2 + 1.5 * math.cos(a1):.4f} -0.99 "
                   f"{-4 + 1.5 * math.sin(a1):.4f} V2 {-2 + 1.5 * math.cos(a0):.4f} -0.99 "
                   f"{-4 + 1.5 * math.sin(a0):.4f} N0 0 1 0 N1 0 1 0 N2 0 1 0 "
                   f"C0 1 1 1 C1 {c1[0]:.3f} {c1[1]:.3f} {c1[2]:.3f} "
                   f"C2 {c0[0]:.3f} {c0[1]:.3f} {c0[2]:.3f} "
                   "AMBIENT 0.2 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 VCST")
    out.append("END_SCENE")


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
    for name, make in (("vmd-helix.dat", helix), ("tachyon-shapes.dat", shapes)):
        lines = []
        make(lines)
        with open(os.path.join(folder, name), "w") as f:
            f.write("\n".join(lines) + "\n")
        print(f"wrote {os.path.join(folder, name)}")


if __name__ == "__main__":
    main()
