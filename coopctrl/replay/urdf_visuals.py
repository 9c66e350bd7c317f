"""The ``<visual>`` geometry of a URDF arm, per body of its chain, for the 3-D replay.

A :class:`~plants.arms.ChainArm` built by :func:`plants.arms.from_urdf` has ``n + 1`` rigid
bodies: body 0 is ``base_link`` (fixed at ``base``) and body ``k`` is the child link of the
``k``-th moving joint from ``base_link`` to ``tip_link``. Every other link reached from
``base_link`` is rigidly attached to one of them: fixed joints, and joints off the chain held at
zero (a hand's fingers), as ``from_urdf`` folds their mass. :func:`urdf_arm_visuals` returns each
visual in its body's frame, ``T_body_visual = T_body_link origin_visual`` [m].

Shapes read: ``box size``, ``cylinder radius length`` (along the visual's z), ``sphere radius``
and ``mesh filename scale`` for STL (binary or ASCII) and OBJ files that are at hand (a path
relative to the URDF file, ``file://`` or ``package://PKG/...`` found in a folder named ``PKG``
above the URDF or beside it). Anything else is left out and said in :attr:`ArmVisuals.notes`.

The file is parsed with ``defusedxml.ElementTree`` (no DTD, no entity expansion, no external
entities), at most :data:`MAX_URDF_BYTES`; meshes are read up to :data:`MAX_MESH_BYTES` each and
:data:`MAX_TRIANGLES` in all.
"""

from __future__ import annotations

import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path

import defusedxml.ElementTree as DET
import numpy as np

from plants.frames import rotation_zyx

#: Largest URDF file read for its visuals [bytes].
MAX_URDF_BYTES = 10_000_000
#: Largest mesh file read [bytes].
MAX_MESH_BYTES = 50_000_000
#: Most triangles of all the meshes of one arm put in the page (beyond, meshes are left out).
MAX_TRIANGLES = 200_000
#: Mesh vertices are rounded to this step in the page [m] (0.1 mm).
MESH_DIGITS = 4


@dataclass(frozen=True)
class Visual:
    """One shape in a body frame.

    Attributes:
        body: Index of the body (0 = ``base_link``, k = child of the k-th moving joint).
        link: The URDF link the visual belongs to.
        shape: ``"box"``, ``"cylinder"``, ``"sphere"`` or ``"mesh"``.
        size: Box ``(x, y, z)``; cylinder ``(radius, length)``; sphere ``(radius,)`` [m];
            ``()`` for a mesh.
        transform: Pose of the shape in the body frame, 4x4 [m].
        dark: True when the URDF's material is dark (luminance < 0.35): drawn dark grey.
        vertices: Mesh vertices (V, 3) in the shape frame [m] (scale applied), or ``None``.
        triangles: Mesh triangles (T, 3) vertex indices, or ``None``.
    """

    body: int
    link: str
    shape: str
    size: tuple
    transform: np.ndarray
    dark: bool = False
    vertices: np.ndarray | None = None
    triangles: np.ndarray | None = None


@dataclass(frozen=True)
class ArmVisuals:
    """The bodies of a URDF arm and their visuals.

    Attributes:
        links: URDF link name of each body (``n + 1``: ``base_link`` first).
        visuals: The shapes, each in its body frame.
        notes: What was left out and why, one line each (an unreadable mesh, an unknown shape).
    """

    links: tuple
    visuals: tuple = ()
    notes: tuple = field(default_factory=tuple)


def _floats(text, count: int, default):
    if text is None:
        return default
    try:
        values = [float(v) for v in str(text).split()]
    except ValueError:
        return None
    if len(values) != count or not np.all(np.isfinite(values)):
        return None
    return values


def _origin(element) -> np.ndarray | None:
    o = element.find("origin") if element is not None else None
    T = np.eye(4)
    if o is None:
        return T
    xyz = _floats(o.get("xyz"), 3, [0.0, 0.0, 0.0])
    rpy = _floats(o.get("rpy"), 3, [0.0, 0.0, 0.0])
    if xyz is None or rpy is None:
        return None
    T[:3, :3] = rotation_zyx(np.array([rpy[2], rpy[1], rpy[0]]))
    T[:3, 3] = xyz
    return T


def _read_urdf(path: Path):
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{path} is not a regular file")
    if st.st_size > MAX_URDF_BYTES:
        raise ValueError(f"{path} has {st.st_size} bytes (at most {MAX_URDF_BYTES} are read)")
    return DET.parse(str(path), forbid_dtd=True).getroot()


def _chain(joints: dict, base_link: str, tip_link: str) -> list:
    """The moving joints from ``base_link`` to ``tip_link`` (bounded walk: a cycle ends it)."""
    by_child = {j.find("child").get("link"): j for j in joints.values()}
    chain, link = [], tip_link
    while link != base_link:
        if link not in by_child or len(chain) > len(joints):
            raise ValueError(f"'{tip_link}' is not below '{base_link}'")
        joint = by_child[link]
        chain.append(joint)
        link = joint.find("parent").get("link")
    return [j for j in reversed(chain) if j.get("type") != "fixed"]


def urdf_arm_visuals(path, base_link: str, tip_link: str) -> ArmVisuals:
    """The bodies and visuals of the arm ``base_link`` .. ``tip_link`` of the URDF ``path``.

    Never raises for a file :func:`plants.arms.from_urdf` accepted; a file it cannot read
    gives no visuals and a note (the arm is then drawn through its joint frames alone).
    """
    path = Path(path)
    try:
        robot = _read_urdf(path)
        joints = {}
        for j in robot.findall("joint"):
            if j.find("parent") is not None and j.find("child") is not None:
                joints[j.get("name")] = j
        moving = _chain(joints, base_link, tip_link)
    except Exception as exc:  # noqa: BLE001 -- any unreadable file: drawn without visuals, said why
        return ArmVisuals(links=(), notes=(f"visuals of {path.name} not read: {type(exc).__name__}: {exc}",))
    body_of_joint = {id(j): k + 1 for k, j in enumerate(moving)}
    links = (base_link, *(j.find("child").get("link") for j in moving))
    materials = _materials(robot)
    children: dict = {}
    for j in joints.values():
        children.setdefault(j.find("parent").get("link"), []).append(j)
    link_elements = {el.get("name"): el for el in robot.findall("link")}

    visuals, notes = [], []
    budget = [MAX_TRIANGLES]
    seen = set()
    todo = [(base_link, 0, np.eye(4))]
    while todo:
        name, body, T = todo.pop()
        if name in seen:  # a link reached twice (a malformed tree): drawn once
            continue
        seen.add(name)
        element = link_elements.get(name)
        for v in element.findall("visual") if element is not None else ():
            shape = _visual(v, name, body, T, path, materials, budget, notes)
            if shape is not None:
                visuals.append(shape)
        for j in children.get(name, []):
            child = j.find("child").get("link")
            if id(j) in body_of_joint:
                todo.append((child, body_of_joint[id(j)], np.eye(4)))
            else:
                origin = _origin(j)
                if origin is not None:
                    todo.append((child, body, T @ origin))  # fixed, or held at zero
    return ArmVisuals(links=links, visuals=tuple(visuals), notes=tuple(notes))


def _materials(robot) -> dict:
    out = {}
    for m in robot.findall("material"):
        rgba = _floats((m.find("color").get("rgba") if m.find("color") is not None else None), 4, None)
        if m.get("name") is not None and rgba is not None:
            out[m.get("name")] = rgba
    return out


def _is_dark(visual, materials: dict) -> bool:
    m = visual.find("material")
    if m is None:
        return False
    color = m.find("color")
    rgba = _floats(color.get("rgba"), 4, None) if color is not None else materials.get(m.get("name"))
    if rgba is None:
        return False
    return 0.2126 * rgba[0] + 0.7152 * rgba[1] + 0.0722 * rgba[2] < 0.35


def _visual(v, link: str, body: int, T_link: np.ndarray, urdf: Path, materials, budget, notes):
    origin = _origin(v)
    geometry = v.find("geometry")
    if origin is None or geometry is None or len(geometry) == 0:
        notes.append(f"link '{link}': a <visual> without a readable <origin> or <geometry> is not drawn")
        return None
    g = geometry[0]
    T = T_link @ origin
    dark = _is_dark(v, materials)
    size = None
    if g.tag == "box":
        size = _floats(g.get("size"), 3, None)
    elif g.tag == "cylinder":
        r, length = _floats(g.get("radius"), 1, None), _floats(g.get("length"), 1, None)
        size = None if r is None or length is None else [r[0], length[0]]
    elif g.tag == "sphere":
        size = _floats(g.get("radius"), 1, None)
    elif g.tag == "mesh":
        return _mesh_visual(g, link, body, T, dark, urdf, budget, notes)
    else:
        notes.append(f"link '{link}': <{g.tag}> is not drawn (box, cylinder, sphere and STL/OBJ meshes are)")
        return None
    if size is None or min(size) <= 0.0:
        notes.append(f"link '{link}': a <{g.tag}> without positive sizes is not drawn")
        return None
    return Visual(body=body, link=link, shape=g.tag, size=tuple(size), transform=T, dark=dark)


def resolve_mesh(filename: str, urdf: Path) -> Path:
    """The file of a ``<mesh filename>``: relative to the URDF's folder, ``file://`` absolute,
    ``package://PKG/REST`` as ``D/REST`` for the nearest folder ``D`` named ``PKG`` above the
    URDF (else ``REST`` beside the URDF)."""
    folder = urdf.resolve().parent
    if filename.startswith("file://"):
        return Path(filename[len("file://"):])
    if filename.startswith("package://"):
        pkg, _, rest = filename[len("package://"):].partition("/")
        for parent in (folder, *folder.parents):
            if parent.name == pkg:
                return parent / rest
        return folder / rest
    return folder / filename


def _mesh_visual(g, link, body, T, dark, urdf, budget, notes):
    filename = g.get("filename") or ""
    scale = _floats(g.get("scale"), 3, [1.0, 1.0, 1.0])
    where = f"link '{link}': mesh {filename!r}"
    if scale is None:
        notes.append(f"{where} has an unreadable scale: not drawn")
        return None
    suffix = os.path.splitext(filename)[1].lower()
    if suffix not in (".stl", ".obj"):
        notes.append(f"{where} is not drawn (STL and OBJ meshes are)")
        return None
    try:
        file = resolve_mesh(filename, urdf)
        st = os.stat(file)
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_MESH_BYTES:
            raise ValueError(f"not a regular file of at most {MAX_MESH_BYTES} bytes")
        data = file.read_bytes()
        vertices, triangles = read_stl(data) if suffix == ".stl" else read_obj(data.decode("utf-8", "replace"))
    except (OSError, ValueError) as exc:
        notes.append(f"{where} is not drawn ({exc})")
        return None
    if len(triangles) > budget[0]:
        notes.append(f"{where} is not drawn: {len(triangles)} triangles, beyond the page's budget of {MAX_TRIANGLES}")
        return None
    budget[0] -= len(triangles)
    vertices = np.round(vertices * np.asarray(scale), MESH_DIGITS)
    vertices, inverse = np.unique(vertices, axis=0, return_inverse=True)  # STL repeats every vertex
    triangles = inverse.reshape(-1)[triangles]
    return Visual(body=body, link=link, shape="mesh", size=(), transform=T, dark=dark,
                  vertices=vertices, triangles=triangles.astype(np.int64))


def read_stl(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (3T, 3) and triangles (T, 3) of a binary or ASCII STL file's bytes."""
    if len(data) >= 84:
        count = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if 84 + 50 * count == len(data):
            record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
            v = np.frombuffer(data, record, count, 84)["v"].astype(float).reshape(-1, 3)
            return _checked(v, np.arange(3 * count).reshape(-1, 3))
    text = data.decode("ascii", "replace")
    if not text.lstrip().startswith("solid"):
        raise ValueError("neither a binary STL (size 84 + 50 per triangle) nor an ASCII STL ('solid ...')")
    number = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
    found = re.findall(rf"vertex\s+({number})\s+({number})\s+({number})", text)
    if not found or len(found) % 3:
        raise ValueError("an ASCII STL without whole triangles")
    v = np.array(found, dtype=float)
    return _checked(v, np.arange(len(v)).reshape(-1, 3))


def read_obj(text: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (T, 3) of a Wavefront OBJ text (``v`` and ``f`` lines;
    polygons fanned into triangles; negative indices count from the end)."""
    vertices, triangles = [], []
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v" and len(parts) >= 4:
            vertices.append([float(p) for p in parts[1:4]])
        elif parts[0] == "f" and len(parts) >= 4:
            idx = []
            for p in parts[1:]:
                i = int(p.split("/")[0])
                idx.append(i - 1 if i > 0 else len(vertices) + i)
            triangles.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    if not vertices or not triangles:
        raise ValueError("an OBJ file without 'v' and 'f' lines")
    return _checked(np.array(vertices, float), np.array(triangles, dtype=np.int64))


def _checked(v: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if not np.all(np.isfinite(v)):
        raise ValueError("non-finite vertex coordinates")
    if tri.size and (tri.min() < 0 or tri.max() >= len(v)):
        raise ValueError("a face index outside the vertex list")
    return v, tri
