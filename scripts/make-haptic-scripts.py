#!/usr/bin/python3
"""Writes the scripted hand trajectories of data/haptics/ from the parametric vertebrae.

    spinesim mesh vertebrae --out /tmp/vertebrae
    spinesim mesh disc --level L4-L5 --cell-size 2.5 --out /tmp/disc-L4-L5.vtu
    scripts/make-haptic-scripts.py /tmp/vertebrae data/haptics /tmp/disc-L4-L5.vtu

The trajectories are set-points of the simulated hand (t_s, x_mm, y_mm, z_mm, button) in the
scene frame (x lateral, y up, z anterior), for a probe of radius 4 mm:
  stroke_spinous.csv  down the spinous process tips T1 -> L5, the set-point 2 mm into them;
  press_lumbar.csv    each lumbar body pressed 3 mm from the front, held, released;
  press_plane.csv     the plane scene (z = 0, normal +z) pressed 3 mm at two spots;
  drag_t1_{lateral,sagittal,oblique}.csv  the compliant stage (thesis 4.5, 6.3): the hand comes to
                      T1's spinous tip from behind, presses the button there, drags T1 40 mm
                      (to the left, backwards, or left-up-backwards), holds, brings it back and
                      lets go.
  twist_t1_axial.csv  the 6-DOF hook: as the drags, but the hand stays at the tip and turns the
                      stylus 30 deg about the spine's long axis (y), holds, turns back, lets go
                      (columns rx_deg,ry_deg,rz_deg: the stylus's rotation vector).
  press_disc_l4l5.csv the L4-L5 disc (scene disc) pressed at its anterior wall at mid-height,
                      along the disc's anterior axis: 2 mm, then 4 mm past first touch, each held
                      (needs the disc mesh and /usr/bin/python3's meshio).
"""
import os
import sys

RADIUS = 4.0


def load_obj(path):
    vertices = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vertices.append(tuple(float(x) for x in line.split()[1:4]))
    return vertices


def write(path, header, rows, rotations=None):
    """rows: (t, x, y, z[, button]); rotations: one (rx, ry, rz) in degrees per row, or None."""
    with open(path, "w") as f:
        f.write("# spinesim haptic script (scripts/make-haptic-scripts.py): " + header + "\n")
        f.write("# units: s, mm, deg; frame x lateral (right = -x), y superior, z anterior; probe radius 4 mm\n")
        f.write("t_s,x_mm,y_mm,z_mm,button" + (",rx_deg,ry_deg,rz_deg" if rotations else "") + "\n")
        for k, row in enumerate(rows):
            t, x, y, z = row[:4]
            button = row[4] if len(row) > 4 else 0
            turn = "".join(f",{a:.3f}" for a in rotations[k]) if rotations else ""
            f.write(f"{t:.3f},{x:.3f},{y:.3f},{z:.3f},{button}{turn}\n")


def main():
    src, out = sys.argv[1], sys.argv[2]
    names = [f"T{i}" for i in range(1, 13)] + [f"L{i}" for i in range(1, 6)]
    verts = {n: load_obj(os.path.join(src, n + ".obj")) for n in names}

    # Spinous tips: the most posterior (smallest z) vertex near the midline.
    tips = []
    for n in names:
        mid = [v for v in verts[n] if abs(v[0]) < 2.0]
        tips.append(min(mid, key=lambda v: v[2]))
    rows, t = [], 0.0
    first = tips[0]
    rows.append((t, 0.0, first[1], first[2] - 40.0))
    t += 1.0
    for tip in tips:
        rows.append((t, 0.0, tip[1], tip[2] - RADIUS + 2.0))
        t += 0.5
    last = tips[-1]
    rows.append((t + 0.5, 0.0, last[1], last[2] - 40.0))
    write(os.path.join(out, "stroke_spinous.csv"), "stroke down the spinous processes T1-L5", rows)

    # Lumbar bodies: the most anterior vertex near the midline, pressed 3 mm.
    rows, t = [], 0.0
    for n in ["L1", "L2", "L3", "L4", "L5"]:
        mid = [v for v in verts[n] if abs(v[0]) < 2.0]
        front = max(mid, key=lambda v: v[2])
        away = (0.0, front[1], front[2] + 25.0)
        touch = (0.0, front[1], front[2] + RADIUS - 3.0)
        rows += [(t, *away), (t + 0.5, *touch), (t + 1.0, *touch), (t + 1.5, *away)]
        t += 2.0
    write(os.path.join(out, "press_lumbar.csv"), "press each lumbar body 3 mm from the front", rows)

    rows = [(0.0, 0.0, 0.0, 20.0), (1.0, 0.0, 0.0, RADIUS - 3.0), (2.0, 0.0, 0.0, RADIUS - 3.0),
            (3.0, 0.0, 0.0, 20.0), (3.5, 20.0, 10.0, 20.0), (4.5, 20.0, 10.0, RADIUS - 3.0),
            (5.5, 20.0, 10.0, RADIUS - 3.0), (6.5, 20.0, 10.0, 20.0)]
    write(os.path.join(out, "press_plane.csv"), "press the plane 3 mm at two spots", rows)

    # Drags of T1 from its spinous tip: approach, press (button), drag 40 mm, hold, return, let go.
    tip = tips[0]
    touch = (0.0, tip[1], tip[2] - RADIUS + 1.0)
    away = (0.0, tip[1], tip[2] - 30.0)
    cases = {"lateral": (1.0, 0.0, 0.0), "sagittal": (0.0, 0.0, -1.0),
             "oblique": (0.6, 0.3, -0.742)}
    for name, d in cases.items():
        n = sum(c * c for c in d) ** 0.5
        far = tuple(touch[k] + 40.0 * d[k] / n for k in range(3))
        rows = [(0.0, *away, 0), (0.8, *touch, 0), (1.0, *touch, 1), (1.5, *touch, 1),
                (3.5, *far, 1), (4.5, *far, 1), (6.0, *touch, 1), (6.5, *touch, 0),
                (7.5, *away, 0)]
        write(os.path.join(out, f"drag_t1_{name}.csv"),
              f"drag T1 {name}ly 40 mm from its spinous tip (button held 1.0-6.5 s)", rows)

    rows = [(0.0, *away, 0), (0.8, *touch, 0), (1.0, *touch, 1), (1.5, *touch, 1),
            (3.0, *touch, 1), (4.0, *touch, 1), (5.5, *touch, 1), (6.0, *touch, 0),
            (7.0, *away, 0)]
    turns = [(0, 0, 0)] * 4 + [(0, 30, 0), (0, 30, 0)] + [(0, 0, 0)] * 3
    write(os.path.join(out, "twist_t1_axial.csv"),
          "6-DOF: hook T1 at its spinous tip and turn the stylus 30 deg about the long axis "
          "(button held 1.0-6.0 s)", rows, turns)

    if len(sys.argv) > 3:
        write_disc_press(sys.argv[3], out)


def write_disc_press(disc_vtu, out):
    """As studies::disc_anterior_wall: the most anterior node within the middle third of the
    height, in the disc's frame (the VTU's disc_frame: origin, then the x, y, z axes)."""
    import meshio
    import numpy as np
    m = meshio.read(disc_vtu)
    f = np.asarray(m.field_data["disc_frame"], dtype=float).ravel()
    origin, axes = f[:3], f[3:].reshape(3, 3).T  # columns: the local x, y, z axes
    local = (m.points - origin) @ axes
    lo, hi = local[:, 1].min(), local[:, 1].max()
    middle = np.abs(local[:, 1] - 0.5 * (lo + hi)) < (hi - lo) / 6
    wall = m.points[np.where(middle)[0][np.argmax(local[middle, 2])]]
    n = axes[:, 2]
    at = lambda d: tuple(wall + (RADIUS - d) * n)  # probe surface d mm past the wall
    away = at(-12.0)
    rows = [(0.0, *away), (1.0, *at(-1.0)), (2.0, *at(2.0)), (3.0, *at(2.0)), (3.5, *at(-1.0)),
            (4.5, *at(4.0)), (5.5, *at(4.0)), (6.0, *at(-1.0)), (7.0, *away)]
    write(os.path.join(out, "press_disc_l4l5.csv"),
          "press the L4-L5 disc's anterior wall 2 mm, then 4 mm (scene disc)", rows)


if __name__ == "__main__":
    main()
