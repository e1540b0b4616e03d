"""Hull meshes for the BEM solve: parametric hulls, mesh files, and the watertightness checks.

A hull is the *immersed* part of its surface, panelled with flat quadrilaterals, open along the
waterline (the waterplane is not panelled). The parametric hulls are symmetric about the
centre plane (y = 0) and the midship plane (x = 0): only the quarter x ≥ 0, y ≥ 0 is
panelled and the solver mirrors it, which divides the cost of its influence matrices by
about four.

Frames: vertices are stored in the solver's frame (Capytaine's: x forward, y to **port**,
z **up**, origin on the waterline at midship on the centre line), the frame the mesh-file
formats use. Every other argument of this module (the centre of gravity of
:meth:`HullMesh.contains`, the messages) is in the project's body frame, x forward,
y starboard, z down, same origin; :data:`SOLVER_FROM_BODY` converts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ...errors import ParameterError, check_range

#: Body (x fwd, y stbd, z down) → solver (x fwd, y port, z up): a rotation of π about x.
SOLVER_FROM_BODY = np.diag([1.0, -1.0, -1.0])

#: Mesh-file formats Capytaine reads without optional libraries (more with meshio/trimesh).
MESH_FORMATS = ("gdf", "mar", "nemoh", "pnl", "hst", "wamit", "hydrostar", "hams", "nc")


@dataclass(frozen=True)
class HullMesh:
    """The immersed surface of a hull, ready for the solver.

    Attributes
    ----------
    name : str
        Hull name (file stem or parametric description).
    vertices : numpy.ndarray
        (n, 3) vertex coordinates, solver frame (x fwd, y port, z up) [m].
    faces : numpy.ndarray
        (m, 4) vertex indices of each panel, counter-clockwise seen from the water so that the
        normal points out of the hull; a triangle repeats its last vertex.
    quarter : bool
        True when ``vertices``/``faces`` hold only the quarter x ≥ 0, y ≥ 0 of a hull that is
        symmetric about the planes y = 0 and x = 0.
    freeboard : float
        Height of the deck above the waterline [m]: the hull extends to it for the check that
        the centre of gravity lies inside.
    description : str
        Dimensions and shape, for the CSV header and the docs.
    inside : callable or None
        ``inside(p)`` for a body-frame point p (3,) [m]: True when p is inside the hull up to
        the deck. None: the bounding box of the mesh up to the deck is used.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    quarter: bool
    freeboard: float
    description: str
    inside: Callable[[np.ndarray], bool] | None = field(default=None, compare=False)

    def full(self) -> tuple[np.ndarray, np.ndarray]:
        """The whole immersed surface: (vertices (n, 3), faces (m, 4)), solver frame.

        A quarter is mirrored about y = 0 and x = 0 (each reflection reverses the vertex order,
        so the normals keep pointing out), and coincident vertices are merged.
        """
        v, f = self.vertices, self.faces
        if self.quarter:
            for axis in (1, 0):
                m = v.copy()
                m[:, axis] *= -1.0
                f = np.vstack([f, f[:, ::-1] + v.shape[0]])
                v = np.vstack([v, m])
        return _merge_vertices(v, f)

    def contains(self, point_body: np.ndarray) -> bool:
        """True when the body-frame point (x fwd, y stbd, z down) [m] is inside the hull up to
        the deck (:attr:`freeboard` above the waterline)."""
        p = np.asarray(point_body, dtype=float)
        if self.inside is not None:
            return bool(self.inside(p))
        v, _ = self.full()
        s = SOLVER_FROM_BODY @ p
        lo, hi = v.min(axis=0), v.max(axis=0)
        hi = np.array([hi[0], hi[1], max(hi[2], self.freeboard)])
        return bool(np.all(s >= lo - 1e-9) and np.all(s <= hi + 1e-9))


def _merge_vertices(vertices: np.ndarray, faces: np.ndarray, tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices closer than ``tol`` [m] (on a grid of that size) and drop unused ones."""
    key = np.round(vertices / tol).astype(np.int64)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    merged = np.zeros((uniq.shape[0], 3))
    np.add.at(merged, inverse, vertices)
    merged /= np.bincount(inverse, minlength=uniq.shape[0])[:, None]
    return merged, inverse[faces]


# --------------------------------------------------------------------------------------------
# parametric hulls
# --------------------------------------------------------------------------------------------

def _breakpoints(edges: list[float], panel: float) -> np.ndarray:
    """Grid lines through every ``edges`` value, intervals cut into pieces no longer than ``panel``."""
    e = np.unique(np.round(np.asarray(edges, dtype=float), 9))
    pts = [e[:1]]
    for a, b in zip(e[:-1], e[1:]):
        n = max(1, math.ceil((b - a) / panel - 1e-9))
        pts.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(pts)


def union_of_boxes(boxes: list[tuple[float, float, float, float, float, float]], panel: float) -> tuple[np.ndarray, np.ndarray]:
    """Quarter surface (x ≥ 0, y ≥ 0, z ≤ 0) of a union of axis-aligned boxes, solver frame.

    The quarter is cut into a rectilinear grid of cells through every box face, each cell is
    solid when its centre lies in a box, and a panel is laid on every cell face between a solid
    and an empty cell, except on the planes x = 0 and y = 0 (mirrored by the solver) and
    z = 0 (the waterplane). The surface is therefore closed below the waterline by
    construction, with panels no longer than ``panel`` [m]. (A voxel-style mesher written here:
    Capytaine's own predefined meshes offer single boxes and cylinders, not their unions.)

    Parameters
    ----------
    boxes : list of tuple
        (x0, x1, y0, y1, z0, z1) of each box, solver frame (z up) [m]; the parts above z = 0
        and outside the quarter are ignored.
    panel : float
        Largest panel side [m].

    Returns
    -------
    tuple of numpy.ndarray
        Vertices (n, 3) and quadrilateral faces (m, 4).
    """
    bx = np.array(boxes, dtype=float)
    xs = _breakpoints([0.0, *np.clip(bx[:, 0:2], 0, None).ravel()], panel)
    ys = _breakpoints([0.0, *np.clip(bx[:, 2:4], 0, None).ravel()], panel)
    zs = _breakpoints([0.0, *np.clip(bx[:, 4:6], None, 0).ravel()], panel)
    cx, cy, cz = (0.5 * (a[1:] + a[:-1]) for a in (xs, ys, zs))
    X, Y, Z = np.meshgrid(cx, cy, cz, indexing="ij")
    solid = np.zeros(X.shape, dtype=bool)
    for x0, x1, y0, y1, z0, z1 in bx:
        solid |= (X > x0) & (X < x1) & (Y > y0) & (Y < y1) & (Z > z0) & (Z < z1)
    ny, nz = ys.size, zs.size
    Xn, Yn, Zn = np.meshgrid(xs, ys, zs, indexing="ij")
    vertices = np.column_stack([Xn.ravel(), Yn.ravel(), Zn.ravel()])

    def node(i, j, k):
        return (i * ny + j) * nz + k

    faces = []
    padded = np.pad(solid, 1)
    for axis in range(3):
        lo = np.take(padded, range(0, padded.shape[axis] - 1), axis=axis)
        hi = np.take(padded, range(1, padded.shape[axis]), axis=axis)
        sl = [slice(1, -1)] * 3
        sl[axis] = slice(None)
        lo, hi = lo[tuple(sl)], hi[tuple(sl)]
        for sign, mask in ((1, lo & ~hi), (-1, hi & ~lo)):
            idx = np.argwhere(mask)  # plane index along axis = idx[axis]; cell indices on the others
            if axis == 0:
                idx = idx[idx[:, 0] != 0]            # the plane x = 0 is mirrored
            elif axis == 1:
                idx = idx[idx[:, 1] != 0]            # y = 0 mirrored
            else:
                idx = idx[idx[:, 2] != nz - 1]       # z = 0 is the open waterplane
            for a, b, c in idx:
                if axis == 0:   # in-plane axes y, z: y × z = +x
                    q = [node(a, b, c), node(a, b + 1, c), node(a, b + 1, c + 1), node(a, b, c + 1)]
                elif axis == 1:  # z × x = +y
                    q = [node(a, b, c), node(a, b, c + 1), node(a + 1, b, c + 1), node(a + 1, b, c)]
                else:           # x × y = +z
                    q = [node(a, b, c), node(a + 1, b, c), node(a + 1, b + 1, c), node(a, b + 1, c)]
                faces.append(q if sign > 0 else q[::-1])
    f = np.array(faces, dtype=int)
    used = np.unique(f)
    remap = np.full(vertices.shape[0], -1)
    remap[used] = np.arange(used.size)
    return vertices[used], remap[f]


def box_barge(length: float, beam: float, draft: float, panel: float, freeboard: float | None = None) -> HullMesh:
    """Rectangular barge L × B × T [m], panels ≤ ``panel`` [m]; deck ``freeboard`` [m] above
    the waterline (default: the draft)."""
    length, beam, draft, panel = _dims(length, beam, draft, panel)
    fb = draft if freeboard is None else check_range("hull.freeboard", freeboard, lo=0.0, lo_open=True, unit="m")
    v, f = union_of_boxes([(-length / 2, length / 2, -beam / 2, beam / 2, -draft, 0.0)], panel)

    def inside(p: np.ndarray) -> bool:
        return abs(p[0]) <= length / 2 and abs(p[1]) <= beam / 2 and -fb <= p[2] <= draft

    return HullMesh(f"box {length:g}x{beam:g}x{draft:g}", v, f, True, fb,
                    f"box barge L {length:g} m × B {beam:g} m × T {draft:g} m", inside)


def semisubmersible(length: float, width: float, draft: float, column: float, pontoon_width: float,
                    pontoon_height: float, panel: float, freeboard: float | None = None) -> HullMesh:
    """Semi-submersible: two pontoons along x and four square columns at their ends.

    Parameters
    ----------
    length, width : float
        Overall length (pontoon length) and overall width (outer pontoon sides) [m].
    draft : float
        Draft to the pontoon bottom [m].
    column : float
        Side of the square columns [m]; their outer faces are flush with the pontoon ends and
        sides.
    pontoon_width, pontoon_height : float
        Pontoon cross-section [m].
    panel : float
        Largest panel side [m].
    freeboard : float, optional
        Column top above the waterline [m] (default: a quarter of the draft).
    """
    length, width, draft, panel = _dims(length, width, draft, panel)
    for name, val in (("hull.column", column), ("hull.pontoon_width", pontoon_width), ("hull.pontoon_height", pontoon_height)):
        check_range(name, val, lo=0.0, lo_open=True, unit="m")
    if pontoon_height >= draft or 2 * pontoon_width >= width or 2 * column >= length or column > width / 2:
        raise ParameterError("semi-submersible: the pontoons and columns do not fit in the given length, width and draft")
    fb = 0.25 * draft if freeboard is None else check_range("hull.freeboard", freeboard, lo=0.0, lo_open=True, unit="m")
    yc = width / 2 - pontoon_width / 2          # pontoon centre line
    xc = length / 2 - column / 2                 # column centre
    boxes = [(-length / 2, length / 2, yc - pontoon_width / 2, yc + pontoon_width / 2, -draft, -draft + pontoon_height)]
    ycol = width / 2 - column / 2
    boxes.append((xc - column / 2, xc + column / 2, ycol - column / 2, ycol + column / 2, -draft, 0.0))
    v, f = union_of_boxes(boxes, panel)

    def inside(p: np.ndarray) -> bool:
        # the structure's envelope: a semi-submersible's COG lies between its columns, held by
        # the braces and the deck box, not inside a column
        return abs(p[0]) <= length / 2 and abs(p[1]) <= width / 2 and -fb <= p[2] <= draft

    return HullMesh(f"semisub {length:g}x{width:g}x{draft:g}", v, f, True, fb,
                    f"semi-submersible {length:g} m × {width:g} m, draft {draft:g} m: two pontoons "
                    f"{pontoon_width:g} × {pontoon_height:g} m, four square columns {column:g} m", inside)


def ship_hull(length: float, beam: float, draft: float, panel: float, p: float = 2.0, q: float = 2.0,
              freeboard: float | None = None) -> HullMesh:
    """Wigley-type ship hull y = ±B/2 · (1 − |2x/L|^p)(1 − |z/T|^q), quarter panelled.

    p = q = 2 is the classical Wigley hull (block coefficient 4/9); larger exponents give
    fuller ends (p) and fuller sections (q): C_B = p/(p+1) · q/(q+1). Stations are uniform in
    x; the points along each section are spaced uniformly in arc length of the midship section
    so that panels near the bilge are not stretched. Above the waterline the sides are vertical
    up to the deck (``freeboard`` [m], default the draft).
    """
    length, beam, draft, panel = _dims(length, beam, draft, panel)
    check_range("hull.p", p, lo=1.0, hi=20.0)
    check_range("hull.q", q, lo=1.0, hi=20.0)
    fb = draft if freeboard is None else check_range("hull.freeboard", freeboard, lo=0.0, lo_open=True, unit="m")
    nx = max(2, math.ceil(length / 2 / panel))
    xi = np.linspace(0.0, 1.0, nx + 1)
    # arc length of the midship section z ↦ y, sampled finely, inverted for uniform spacing
    zeta_f = np.linspace(0.0, 1.0, 2001)
    yf = beam / 2 * (1 - zeta_f**q)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(yf), np.diff(zeta_f) * draft))])
    nz = max(2, math.ceil(s[-1] / panel))
    zeta = np.interp(np.linspace(0.0, s[-1], nz + 1), s, zeta_f)
    XI, ZE = np.meshgrid(xi, zeta, indexing="ij")
    Y = beam / 2 * (1 - XI**p) * (1 - ZE**q)
    vertices = np.column_stack([(XI * length / 2).ravel(), Y.ravel(), (-ZE * draft).ravel()])
    n = nz + 1
    faces = []
    for i in range(nx):
        for j in range(nz):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            faces.append([a, b, c, d])     # (+x) × (−z) = +y: out of the hull on the quarter's side
    v, f = vertices, np.array(faces, dtype=int)
    # the stem (x = L/2) and the keel (z = −T) have y = 0 and merge with the mirrored half;
    # collapse the panels that degenerate there into triangles (last vertex repeated)
    v, f = _merge_vertices(v, f)
    f = np.array([_as_panel(row) for row in f])
    f = f[[len(set(row)) >= 3 for row in f]]

    def inside(pt: np.ndarray) -> bool:
        x, y, zdown = abs(pt[0]), abs(pt[1]), pt[2]
        if x > length / 2 or zdown > draft or zdown < -fb:
            return False
        zeta_p = max(zdown, 0.0) / draft
        return y <= beam / 2 * (1 - (2 * x / length) ** p) * (1 - zeta_p**q)

    cb = p / (p + 1) * q / (q + 1)
    return HullMesh(f"ship {length:g}x{beam:g}x{draft:g}", v, f, True, fb,
                    f"Wigley-type hull L {length:g} m × B {beam:g} m × T {draft:g} m, "
                    f"y = B/2 (1 − |2x/L|^{p:g})(1 − |z/T|^{q:g}), C_B {cb:.3f}", inside)


def hemisphere(radius: float, panel: float, freeboard: float | None = None) -> HullMesh:
    """Floating hemisphere of ``radius`` [m] (the classical test body of Hulme 1982), panels of
    about ``panel`` [m] on a latitude-longitude grid of the quarter; vertical sides up to the
    deck ``freeboard`` [m] above the waterline (default: the radius)."""
    radius = check_range("hull.radius", radius, lo=0.0, lo_open=True, unit="m")
    panel = check_range("hull.panel", panel, lo=0.0, lo_open=True, unit="m")
    fb = radius if freeboard is None else check_range("hull.freeboard", freeboard, lo=0.0, lo_open=True, unit="m")
    n = max(2, math.ceil(0.5 * math.pi * radius / panel))
    theta = np.linspace(0.0, 0.5 * math.pi, n + 1)     # from the waterline down to the bottom pole
    phi = np.linspace(0.0, 0.5 * math.pi, n + 1)       # from +x towards +y
    TH, PH = np.meshgrid(theta, phi, indexing="ij")
    vertices = np.column_stack([(radius * np.cos(TH) * np.cos(PH)).ravel(), (radius * np.cos(TH) * np.sin(PH)).ravel(),
                                (-radius * np.sin(TH)).ravel()])
    m = n + 1
    # (+θ, downwards) × (+φ) points out of the sphere
    faces = [[i * m + j, (i + 1) * m + j, (i + 1) * m + j + 1, i * m + j + 1] for i in range(n) for j in range(n)]
    v, f = _merge_vertices(vertices, np.array(faces, dtype=int))
    f = np.array([_as_panel(row) for row in f])
    f = f[[len(set(row)) >= 3 for row in f]]

    def inside(p: np.ndarray) -> bool:
        r = math.hypot(p[0], p[1])
        return (r <= radius and -fb <= p[2] <= 0.0) or (p[2] >= 0.0 and math.hypot(r, p[2]) <= radius)

    return HullMesh(f"hemisphere r{radius:g}", v, f, True, fb, f"floating hemisphere, radius {radius:g} m", inside)


def _as_panel(row: np.ndarray) -> list[int]:
    """Drop repeated consecutive vertices of a quad; a triangle repeats its last vertex."""
    out: list[int] = []
    for k in row.tolist():
        if not out or out[-1] != k:
            out.append(k)
    if len(out) > 1 and out[0] == out[-1]:
        out.pop()
    while len(out) < 4:
        out.append(out[-1])
    return out


def _dims(length: float, beam: float, draft: float, panel: float) -> tuple[float, float, float, float]:
    length = check_range("hull.length", length, lo=0.0, lo_open=True, unit="m")
    beam = check_range("hull.beam", beam, lo=0.0, lo_open=True, unit="m")
    draft = check_range("hull.draft", draft, lo=0.0, lo_open=True, unit="m")
    panel = check_range("hull.panel", panel, lo=0.0, lo_open=True, unit="m")
    return length, beam, draft, panel


def load_mesh_file(path: str | Path, freeboard: float | None = None) -> HullMesh:
    """A hull from a mesh file in a format Capytaine reads (:data:`MESH_FORMATS`; STL, OBJ and
    more with the optional meshio or trimesh).

    The file must be in the solver's frame (x forward, y to port, z up, waterline z = 0), as
    these formats are. The part above the waterline, if any, is clipped off. The result is
    refused by :func:`check_closed` if it is not closed below the waterline.

    Parameters
    ----------
    path : str or pathlib.Path
        Mesh file.
    freeboard : float, optional
        Deck height above the waterline [m] for the centre-of-gravity check (default: the
        highest vertex of the file, or the draft if the file holds only the immersed part).
    """
    import capytaine as cpt  # optional dependency: only here

    path = Path(path)
    if not path.is_file():
        raise ParameterError(f"hull mesh file {str(path)!r} does not exist")
    try:
        mesh = cpt.load_mesh(str(path))
    except Exception as exc:  # the readers raise ValueError, KeyError, IndexError… on bad files
        raise ParameterError(f"hull mesh file {str(path)!r} cannot be read: {exc}") from exc
    mesh = mesh.merged() if hasattr(mesh, "merged") else mesh
    if mesh.nb_faces == 0:
        raise ParameterError(f"hull mesh file {str(path)!r} holds no panel")
    top = float(mesh.vertices[:, 2].max())
    draft = -float(mesh.vertices[:, 2].min())
    if draft <= 0:
        raise ParameterError(f"hull mesh file {str(path)!r}: no part of the mesh is below the waterline z = 0 "
                             f"(the file's z axis must point up)")
    immersed = mesh.immersed_part() if top > 1e-9 else mesh
    fb = freeboard if freeboard is not None else (top if top > 1e-9 else draft)
    v = np.asarray(immersed.vertices, dtype=float)
    f = np.asarray(immersed.faces, dtype=int)
    v, f = _merge_vertices(v, f)
    f = np.array([_as_panel(row) for row in f])
    f = f[[len(set(row)) >= 3 for row in f]]
    ext = v.max(axis=0) - v.min(axis=0)
    return HullMesh(path.stem, v, f, False, float(fb),
                    f"mesh file {path.name}: {f.shape[0]} panels, {ext[0]:.4g} m × {ext[1]:.4g} m, draft {draft:.4g} m")


def write_gdf(hull: HullMesh, path: str | Path) -> Path:
    """Write the whole immersed surface as a WAMIT GDF file (solver frame, no symmetry flags),
    e.g. to inspect a parametric hull or to start a mesh of one's own."""
    v, f = hull.full()
    path = Path(path)
    lines = [f"marinefmu hull {hull.name}: {hull.description}", "1.0 9.80665", "0 0", str(f.shape[0])]
    lines += [f"{x:.9g} {y:.9g} {z:.9g}" for row in f for x, y, z in v[row]]
    path.write_text("\n".join(lines) + "\n")
    return path


def check_closed(hull: HullMesh, tol: float = 1e-6) -> float:
    """Refuse a mesh that is not closed below the waterline; return its displaced volume [m³].

    Checked on the whole (mirrored) surface: no panel above the waterline; every edge below
    the waterline shared by exactly two panels, which run along it in opposite directions
    (consistent normals); the open edges on the waterline forming closed curves; and the
    displaced volume computed with the three components of the divergence theorem agreeing
    and positive (normals out of the hull). (Edge bookkeeping written here: Capytaine warns on
    some of these defects but does not refuse them.)

    Raises
    ------
    ParameterError
        Naming the defect and a body-frame point (x fwd, y stbd, z down) [m] near it.
    """
    v, f = hull.full()
    name = f"hull mesh {hull.name!r}"
    scale = float(np.ptp(v, axis=0).max()) or 1.0
    eps = tol * scale
    if v[:, 2].max() > eps:
        i = int(np.argmax(v[:, 2]))
        raise ParameterError(f"{name}: vertices above the waterline remain after clipping, e.g. at {_where(v[i])}")
    directed: dict[tuple[int, int], int] = {}
    for row in f:
        ring = list(dict.fromkeys(row.tolist())) if len(set(row.tolist())) < 4 else row.tolist()
        for a, b in zip(ring, ring[1:] + ring[:1]):
            if a != b:
                directed[(a, b)] = directed.get((a, b), 0) + 1
    undirected: dict[tuple[int, int], int] = {}
    for (a, b), n in directed.items():
        if n > 1:
            raise ParameterError(f"{name}: inconsistent panel orientation (normals) along the edge at {_where(0.5 * (v[a] + v[b]))}")
        key = (min(a, b), max(a, b))
        undirected[key] = undirected.get(key, 0) + n
    open_edges = [e for e, n in undirected.items() if n == 1]
    bad = [e for e, n in undirected.items() if n > 2]
    if bad:
        a, b = bad[0]
        raise ParameterError(f"{name}: {len(bad)} edge(s) shared by more than two panels (not a manifold surface), "
                             f"e.g. at {_where(0.5 * (v[a] + v[b]))}")
    below = [e for e in open_edges if min(v[e[0], 2], v[e[1], 2]) < -eps]
    if below:
        a, b = below[0]
        raise ParameterError(f"{name}: not closed: {len(below)} open edge(s) below the waterline, e.g. at "
                             f"{_where(0.5 * (v[a] + v[b]))}")
    if not open_edges:
        raise ParameterError(f"{name}: no waterline: the mesh is a closed surface under water (a submerged body), "
                             "not a floating hull")
    degree = np.bincount(np.array(open_edges).ravel(), minlength=v.shape[0])
    odd = np.nonzero(degree % 2)[0]
    if odd.size:
        raise ParameterError(f"{name}: not watertight at the waterline: the waterline is not a closed curve near {_where(v[odd[0]])}")
    vols = _volumes(v, f)
    if np.all(vols < 0):
        raise ParameterError(f"{name}: the panel normals point into the hull (displaced volume {vols[2]:.4g} m³ < 0); "
                             "reverse the vertex order of every panel")
    if vols.min() <= 0 or np.ptp(vols) > 0.01 * abs(vols).max():
        raise ParameterError(f"{name}: not watertight: the displaced volume from x, y and z components "
                             f"({vols[0]:.5g}, {vols[1]:.5g}, {vols[2]:.5g} m³) disagree by more than 1 %")
    return float(vols.mean())


def _volumes(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """∮ x n_x dS, ∮ y n_y dS, ∮ z n_z dS over the panels (each = the displaced volume when the
    surface is closed by the waterplane z = 0, where x n_x = y n_y = z n_z = 0)."""
    p = v[f]                                             # (m, 4, 3)
    area_vec = 0.5 * np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])   # n·dS of a flat quad (or triangle)
    centre = p.mean(axis=1)
    tri = f[:, 2] == f[:, 3]
    centre[tri] = p[tri, :3].mean(axis=1)
    return np.sum(centre * area_vec, axis=0)


def _where(point_solver: np.ndarray) -> str:
    b = SOLVER_FROM_BODY @ np.asarray(point_solver, dtype=float)
    return f"(x {b[0]:.3g}, y {b[1]:.3g}, z {b[2]:.3g}) m (body frame: x fwd, y stbd, z down)"
