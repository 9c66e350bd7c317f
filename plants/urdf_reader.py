"""Reading a URDF file safely: the XML document and its link tree, without the numbers.

The file is read with ``defusedxml.ElementTree`` (``forbid_dtd=True``): a document type declaration
-- entity definitions (the "billion laughs" expansion bomb) or external entities (a file or URL
pulled into the document) -- is refused before anything is expanded or fetched. The file must be a
regular file of at most :data:`MAX_URDF_BYTES`. The links must form a tree: unique link and joint
names, each link the child of at most one joint, no cycle (found in linear time), and at most
:data:`MAX_CHAIN_JOINTS` joints between ``base_link`` and ``tip_link``.

This module imports neither the compiled core nor the arm models, so that the scene loader can check a URDF
arm's file (and count its joints) in well under a second, before any long work; the arm itself is
built by :func:`plants.arms.from_urdf`, which reads the numbers on this tree. Errors are
:class:`~plants.errors.ParameterError` naming ``urdf``, ``base_link``, ``tip_link`` or the element
(``joint 'j2'.child``).
"""

from __future__ import annotations

import os
import stat
import xml.etree.ElementTree as ET

import defusedxml
import defusedxml.ElementTree as DET

from plants.errors import ParameterError

#: Largest URDF file read [bytes] (the shipped ones are under 20 kB; meshes are separate files).
MAX_URDF_BYTES = 16 * 1024 * 1024
#: Most joints of a serial arm: between ``base_link`` and ``tip_link`` of a URDF (fixed ones
#: included), or rows of a DH table. Real arms have about a dozen; the bound keeps a hostile
#: 1000-joint chain from building (and compiling) for minutes.
MAX_CHAIN_JOINTS = 64


def read_urdf(path):
    """The ``<robot>`` element of the URDF file ``path`` (module docstring: a regular file of at most
    :data:`MAX_URDF_BYTES`, no DTD or entities, well-formed)."""
    where = os.fspath(path)
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        raise ParameterError("urdf", where, "an existing URDF file") from None
    if not stat.S_ISREG(info.st_mode):
        raise ParameterError("urdf", where, "a regular URDF file (not a directory, device or pipe)")
    if info.st_size > MAX_URDF_BYTES:
        raise ParameterError("urdf", where, f"a URDF file of at most {MAX_URDF_BYTES} bytes (it has {info.st_size})")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_URDF_BYTES + 1)
    except OSError as exc:
        raise ParameterError("urdf", where, f"a readable URDF file ({exc.strerror})") from None
    if len(data) > MAX_URDF_BYTES:
        raise ParameterError("urdf", where, f"a URDF file of at most {MAX_URDF_BYTES} bytes")
    try:
        root = DET.fromstring(data, forbid_dtd=True, forbid_entities=True, forbid_external=True)
    except defusedxml.DefusedXmlException as exc:
        raise ParameterError("urdf", where, "a URDF without a document type declaration, entities or external "
                             f"references (refused for safety: {type(exc).__name__})") from None
    except (ET.ParseError, ValueError) as exc:
        raise ParameterError("urdf", where, f"a well-formed URDF (XML error: {exc})") from None
    if root.tag != "robot":
        raise ParameterError("urdf", where, f"a URDF whose root element is <robot> (got <{root.tag}>)")
    return root


def link_tree(robot, path) -> tuple[dict, dict]:
    """``(links, joints)`` of a ``<robot>``: ``links`` maps each link name to its element, ``joints``
    each joint name to ``dict(name, type, parent, child, element)``; refuses duplicate names, a joint
    without ``<parent link>``/``<child link>`` or naming an unknown link, a link moved by two joints,
    and cycles."""
    links = {}
    for el in robot.findall("link"):
        name = el.get("name")
        if name is None or name in links:
            raise ParameterError(f"link '{name}'.name", name, "a unique link name")
        links[name] = el
    joints: dict[str, dict] = {}
    parent_joint: dict[str, str] = {}
    for el in robot.findall("joint"):
        name = el.get("name")
        where = f"joint '{name}'"
        if name is None or name in joints:
            raise ParameterError(f"{where}.name", name, "a unique joint name")
        parent, child = el.find("parent"), el.find("child")
        if parent is None or child is None:
            raise ParameterError(where, None, "<parent link> and <child link>")
        joint = dict(name=name, type=el.get("type"), parent=parent.get("link"), child=child.get("link"), element=el)
        for key in ("parent", "child"):
            if joint[key] not in links:
                raise ParameterError(f"{where}.{key}", joint[key], f"a link of {os.fspath(path)}")
        if joint["child"] in parent_joint:
            raise ParameterError(f"{where}.child", joint["child"], "a link that no other joint moves (a tree: joint "
                                 f"'{parent_joint[joint['child']]}' already has it as its child)")
        parent_joint[joint["child"]] = name
        joints[name] = joint
    _check_acyclic(joints, parent_joint)
    return links, joints


def _check_acyclic(joints, parent_joint) -> None:
    """Refuse links that are their own ancestors (each link has at most one parent joint, so a walk
    up from any link either ends at a root or comes back: linear time with the finished marks)."""
    done: set = set()
    for start in parent_joint:
        path, on_path, link = [], set(), start
        while link in parent_joint and link not in done:
            if link in on_path:
                names = [parent_joint[c] for c in path[path.index(link):]]
                raise ParameterError(f"joint '{names[0]}'.parent", joints[names[0]]["parent"],
                                     f"a link tree without cycles (the joints {names} form a cycle)")
            on_path.add(link)
            path.append(link)
            link = joints[parent_joint[link]]["parent"]
        done.update(path)


def kinematic_chain(links, joints, base_link: str, tip_link: str, path) -> list[dict]:
    """The joints of :func:`link_tree` from ``base_link`` down to ``tip_link``, in order (at most
    :data:`MAX_CHAIN_JOINTS`)."""
    for field_name, link in (("base_link", base_link), ("tip_link", tip_link)):
        if link not in links:
            names = sorted(links)
            more = ", ..." if len(names) > 6 else ""
            raise ParameterError(field_name, link, f"a link of {os.fspath(path)} (it has {', '.join(names[:6])}{more})")
    by_child = {j["child"]: j for j in joints.values()}
    chain: list[dict] = []
    link = tip_link
    while link != base_link:
        if link not in by_child:  # not below base_link (link_tree has refused cycles)
            raise ParameterError("tip_link", tip_link, f"a link below base_link '{base_link}' in the kinematic tree")
        if len(chain) >= MAX_CHAIN_JOINTS:
            raise ParameterError("tip_link", tip_link, f"a link at most {MAX_CHAIN_JOINTS} joints below base_link "
                                 f"'{base_link}' (a serial arm, not a chain of more than {MAX_CHAIN_JOINTS} joints)")
        j = by_child[link]
        chain.append(j)
        link = j["parent"]
    chain.reverse()
    return chain


def chain_dof(path, base_link: str, tip_link: str) -> int:
    """Moving (non-fixed) joints between ``base_link`` and ``tip_link`` of the URDF file ``path``,
    with the checks of this module."""
    links, joints = link_tree(read_urdf(path), path)
    return sum(j["type"] != "fixed" for j in kinematic_chain(links, joints, base_link, tip_link, path))
