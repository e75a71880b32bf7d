#!/usr/bin/env python3
"""Converts an NFF scene (Eric Haines' NFF.TXT) to Tachyon's .dat so that Tachyon renders it as
glint reads NFF (docs/scene-format.md), for bench/spd_bench.sh. Tachyon's own NFF reader departs
from the format (its field of view ignores `angle`, gears render blank), so the benchmark times
Tachyon on this conversion instead:

  - camera: from/at/up; the view plane at distance 1 on which the centres of the top and bottom
    pixel rows lie `angle` apart (square pixels), given to Tachyon as a FRUSTUM shifted by half a
    pixel: Tachyon samples each pixel at its top-right corner, glint at its centre;
  - Tachyon's camera is left-handed, so the scene is mirrored in x (as glint's .dat reader does the
    other way), and Tachyon shows what glint shows;
  - lights: point lights of colour × 1/sqrt(number of lights), no ambient;
  - `f r g b Kd Ks Shine T ior`: AMBIENT 0, DIFFUSE Kd, COLOR r g b (diffuse = Kd·colour),
    SPECULAR Ks (mirror), PHONG PLASTIC Ks PHONG_SIZE Shine (white highlight), OPACITY 1 − T;
    Tachyon has no refraction (its transmitted rays go straight on), the one term that differs;
  - s → SPHERE, c → FCYLINDER when both radii are equal, else the cone's side as smooth triangles
    (Tachyon has no cone), p → TRI (triangulated, concave ones by ear clipping), pp → STRI.
  - RAYDEPTH 5 (the SPD procedure), ANTIALIASING 0.

  usage: nff_to_tachyon.py IN.nff OUT.dat
"""
import math
import sys

CONE_SEGMENTS = 48


def tokens(text):
    for line in text.splitlines():
        line = line.split("#", 1)[0]
        yield from line.split()


def mirror(p):
    return (-p[0], p[1], p[2])


def fmt(v):
    return " ".join(f"{x:.9g}" for x in v)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def norm(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a) if n > 0 else a


def triangulate(points):
    """Ear clipping of a planar polygon (the vertex order kept), as glint's NFF reader does."""
    n = len(points)
    normal = [0.0, 0.0, 0.0]
    for i in range(n):
        a, b = points[i], points[(i + 1) % n]
        normal[0] += (a[1] - b[1]) * (a[2] + b[2])
        normal[1] += (a[2] - b[2]) * (a[0] + b[0])
        normal[2] += (a[0] - b[0]) * (a[1] + b[1])
    if dot(normal, normal) == 0:
        return []
    if n == 3:
        return [(0, 1, 2)]
    an = [abs(x) for x in normal]
    drop = 0 if an[0] >= an[1] and an[0] >= an[2] else (1 if an[1] >= an[2] else 2)
    sign = 1 if normal[drop] > 0 else -1
    u = lambda i: points[i][(drop + 1) % 3]
    w = lambda i: points[i][(drop + 2) % 3]

    def turn(a, b, c):
        return sign * ((u(b) - u(a)) * (w(c) - w(a)) - (w(b) - w(a)) * (u(c) - u(a)))

    ring = list(range(n))
    out = []
    while len(ring) > 3:
        m = len(ring)
        for i in range(m):
            a, b, c = ring[(i - 1) % m], ring[i], ring[(i + 1) % m]
            if not turn(a, b, c) > 0:
                continue
            if any(q not in (a, b, c) and turn(a, b, q) >= 0 and turn(b, c, q) >= 0 and
                   turn(c, a, q) >= 0 for q in ring):
                continue
            out.append((a, b, c))
            del ring[i]
            break
        else:
            out += [(ring[0], ring[k], ring[k + 1]) for k in range(1, len(ring) - 1)]
            return out
    out.append(tuple(ring))
    return out


def stri(p, n, texture):
    """A smooth triangle wound to face its normals: Tachyon turns a smooth triangle's normal to the
    side its winding faces the viewer from, and the mirror in x reverses every winding."""
    if dot(cross(sub(p[1], p[0]), sub(p[2], p[0])), tuple(map(sum, zip(*n)))) < 0:
        p = (p[0], p[2], p[1])
        n = (n[0], n[2], n[1])
    return (f"STRI V0 {fmt(p[0])} V1 {fmt(p[1])} V2 {fmt(p[2])} "
            f"N0 {fmt(n[0])} N1 {fmt(n[1])} N2 {fmt(n[2])} {texture}")


def cone_triangles(base, r0, apex, r1):
    """The open cone's side as STRI triangles with the cone's exact normals."""
    axis = sub(apex, base)
    h = math.sqrt(dot(axis, axis))
    a = norm(axis)
    ref = (1, 0, 0) if abs(a[0]) < 0.9 else (0, 1, 0)
    u = norm(sub(ref, tuple(x * dot(ref, a) for x in a)))
    v = cross(a, u)
    k = (r1 - r0) / h
    out = []
    for i in range(CONE_SEGMENTS):
        rim = []
        for j in (i, i + 1):
            phi = 2 * math.pi * j / CONE_SEGMENTS
            d = tuple(math.cos(phi) * x + math.sin(phi) * y for x, y in zip(u, v))
            n = norm(tuple(x - k * y for x, y in zip(d, a)))
            rim.append((tuple(b + r0 * x for b, x in zip(base, d)),
                        tuple(p + r1 * x for p, x in zip(apex, d)), n))
        (b0, t0, n0), (b1, t1, n1) = rim
        out.append(((b0, b1, t1), (n0, n1, n1)))
        out.append(((b0, t1, t0), (n0, n1, n0)))
    return out


class Tokens:
    def __init__(self, text):
        self.items = list(tokens(text))
        self.i = 0

    def __bool__(self):
        return self.i < len(self.items)

    def next(self):
        self.i += 1
        return self.items[self.i - 1]

    def numbers(self, n):
        return [float(self.next()) for _ in range(n)]

    def number_follows(self):
        try:
            float(self.items[self.i])
            return True
        except (IndexError, ValueError):
            return False


def convert(text):
    t = Tokens(text)
    out = []
    view = {}
    lights = []
    background = (0, 0, 0)
    body = []
    textures = 0
    current = None
    while t:
        word = t.next()
        if word == "v":
            for key, n in (("from", 3), ("at", 3), ("up", 3), ("angle", 1), ("hither", 1),
                           ("resolution", 2)):
                assert t.next() == key, key
                view[key] = t.numbers(n)
        elif word == "b":
            background = t.numbers(3)
        elif word == "l":
            p = t.numbers(3)
            lights.append((p, t.numbers(3) if t.number_follows() else None))
        elif word == "f":
            r, g, b, kd, ks, shine, tr, _ior = t.numbers(8)
            textures += 1
            current = f"fill{textures}"
            phong = f" PHONG PLASTIC {ks:.9g} PHONG_SIZE {shine:.9g}" if ks > 0 else ""
            body.append(f"TEXDEF {current} AMBIENT 0 DIFFUSE {kd:.9g} SPECULAR {ks:.9g} "
                        f"OPACITY {1 - tr:.9g}{phong} COLOR {r:.9g} {g:.9g} {b:.9g} TEXFUNC 0")
        elif word == "s":
            x, y, z, r = t.numbers(4)
            body.append(f"SPHERE CENTER {fmt(mirror((x, y, z)))} RAD {abs(r):.9g} {current}")
        elif word == "c":
            b = t.numbers(4)
            a = t.numbers(4)
            r0, r1 = abs(b[3]), abs(a[3])
            base, apex = mirror(b[:3]), mirror(a[:3])
            if r0 == r1:
                body.append(f"FCYLINDER BASE {fmt(base)} APEX {fmt(apex)} RAD {r0:.9g} {current}")
            else:
                for p, n in cone_triangles(base, r0, apex, r1):
                    body.append(stri(p, n, current))
        elif word in ("p", "pp"):
            count = int(t.next())
            verts, normals = [], []
            for _ in range(count):
                verts.append(tuple(t.numbers(3)))
                if word == "pp":
                    normals.append(tuple(t.numbers(3)))
            for tri in triangulate(verts):
                p = tuple(mirror(verts[q]) for q in tri)
                if word == "p":
                    body.append(f"TRI V0 {fmt(p[0])} V1 {fmt(p[1])} V2 {fmt(p[2])} {current}")
                else:
                    body.append(stri(p, tuple(mirror(normals[q]) for q in tri), current))
        else:
            raise SystemExit(f"nff_to_tachyon: unknown NFF statement {word!r}")

    cols, rows = (int(x) for x in view["resolution"])
    span = 2 * math.tan(math.radians(view["angle"][0]) / 2)
    pitch = span / (rows - 1) if rows > 1 else span
    width, height = pitch * cols, pitch * rows
    eye, at, up = mirror(view["from"]), mirror(view["at"]), mirror(view["up"])
    intensity = 1 / math.sqrt(len(lights)) if lights else 0
    out.append("BEGIN_SCENE")
    out.append(f"RESOLUTION {cols} {rows}")
    out.append("CAMERA")
    out.append(f"  ZOOM {1 / height:.12g}")
    out.append("  ASPECTRATIO 1")
    out.append("  ANTIALIASING 0")
    out.append("  RAYDEPTH 5")
    out.append(f"  CENTER {fmt(eye)}")
    out.append(f"  VIEWDIR {fmt(sub(at, eye))}")
    out.append(f"  UPDIR {fmt(up)}")
    # left right bottom top, half a pixel down and left: samples at the pixel centres.
    out.append(f"  FRUSTUM {-width / 2 - pitch / 2:.12g} {width / 2 - pitch / 2:.12g} "
               f"{-height / 2 - pitch / 2:.12g} {height / 2 - pitch / 2:.12g}")
    out.append("END_CAMERA")
    out.append(f"BACKGROUND {fmt(background)}")
    for p, c in lights:
        c = c or (1, 1, 1)
        out.append(f"LIGHT CENTER {fmt(mirror(p))} RAD 0 COLOR {fmt(tuple(x * intensity for x in c))}")
    out += body
    out.append("END_SCENE")
    return "\n".join(out) + "\n"


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    with open(sys.argv[1]) as f:
        text = f.read()
    with open(sys.argv[2], "w") as f:
        f.write(convert(text))


if __name__ == "__main__":
    main()
