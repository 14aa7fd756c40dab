"""SMURF (`.smurf` + its URDF or SDF + `<name>_<category>.yml` files) → ir.Robot.

The `.smurf` lists its files; exactly one of them is the URDF or SDF, read by that
format's reader. Each annotation file is a mapping `{category: content}` whose entries
name elements of that model: motors, sensors, poses, loop-closure joints, submechanisms
and exoskeletons are added; annotations, bitmasks and material properties are set on the
elements they name; any other category is a free annotation category. Whatever is wrong
(a file that is not there, a malformed entry, a name the model lacks) is a diagnostic
with its file:line:col. Phobos's SMURFs read the same way: entries keyed by name (a
collision found through the model file, wherever its link), colours and offsets as lists
or mappings (backends/smurf_forms.py). The keys the model file holds or that follow from
it (a joint's parent, child and type, a link's shape names, a motor's maxEffort … from its
joint's limits, a material's transparency from its alpha) are not kept as annotations, so
that reading and writing again gives the same files; every other key is kept.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

from mpc.backends.smurf_forms import (
    MATERIAL_COLOURS,
    MATERIAL_SCALARS,
    MOTOR_TYPE,
    colour_in,
    floats,
    motor_limits,
    number,
    orientation_in,
    position_in,
    shape_names,
)
from mpc.core import yaml_source as source
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.packages import PackageResolver
from mpc.core.span import Span
from mpc.ir.extras import CutJoint, Motor, Sensor, Submechanism
from mpc.ir.robot import Material, Pose, Robot

MODEL_SUFFIXES = (".urdf", ".sdf")


def read(path: Path, sink: Sink, resolver: PackageResolver | None = None) -> Robot | None:
    """Read the SMURF at `path`; None when it has errors (all of them reported)."""
    doc = source.load(path, sink)
    if doc is None:
        return None
    before = sink.error_count
    robot = _Reader(doc, path, sink, resolver or PackageResolver()).robot()
    return None if robot is None or sink.error_count > before else robot


# Keys of a tree joint's entry that its model file holds (Phobos writes them all); the
# first three are compared with the model, the others are left to it.
_JOINT_CHECKED = (("parent", "parent"), ("child", "child"), ("joint_type", "type"))
_JOINT_DERIVED = ("origin", "joint_relative_origin", "joint_dependencies", "axis", "limit", "dynamics",
                  "mimic", "motor")
# Keys of a visual's or collision's entry that its model file holds.
_SHAPE_DERIVED = ("geometry", "origin", "joint_relative_origin", "material", "primitives", "link")


class _Reader:
    def __init__(self, doc: source.Document, path: Path, sink: Sink, resolver: PackageResolver) -> None:
        self.smurf, self.path, self.sink, self.resolver = doc, path, sink, resolver
        self.doc = doc  # the file being read

    def error(self, where: tuple[str | int, ...], code: str, message: str) -> None:
        self.sink.error(self.doc.value_span(where), code, message)

    # -- the .smurf ------------------------------------------------------------------------

    def robot(self) -> Robot | None:
        data = self.smurf.data
        files = data.get("files") if isinstance(data, dict) else None
        if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
            where: tuple[str | int, ...] = ("files",) if isinstance(data, dict) and "files" in data else ()
            self.error(where, "E0512", "a SMURF file is a mapping whose 'files' lists its URDF or SDF "
                       "and its annotation files (paths relative to the .smurf)")
            return None
        models = [i for i, f in enumerate(files) if Path(f).suffix.lower() in MODEL_SUFFIXES]
        if len(models) != 1:
            what = ("lists no URDF or SDF file" if not models else
                    f"lists {len(models)} model files ({', '.join(files[i] for i in models)}); it links one, "
                    "the others belong in 'additional_files'")
            self.error(("files", models[1]) if models else ("files",), "E0513", f"the SMURF {what}")
            return None
        robot = self.model(files[models[0]], ("files", models[0]))
        if robot is None:
            return None
        self.state = _State(robot)
        for i, name in enumerate(files):
            if i != models[0]:
                self.annotation_file(name, ("files", i))
        return self.state.robot()

    def listed(self, name: str, where: tuple[str | int, ...]) -> Path | None:
        path = (self.path.parent / name).resolve()
        if not path.is_file():
            self.sink.error(self.smurf.value_span(where), "E0601", f"'{name}', listed in the SMURF, "
                            "does not exist")
            return None
        if why := self.resolver.refusal(self.path.parent / name, self.path.parent):
            self.sink.error(self.smurf.value_span(where), "E0650", f"'{name}', listed in the SMURF, "
                            f"is not read: {why}")
            return None
        return path

    def model(self, name: str, where: tuple[str | int, ...]) -> Robot | None:
        from mpc.backends import sdf_reader, urdf_reader

        path = self.listed(name, where)
        if path is None:
            return None
        reader = sdf_reader if path.suffix.lower() == ".sdf" else urdf_reader  # a SMURF lists no SMURF
        return reader.read(path, self.sink, self.resolver)

    def annotation_file(self, name: str, where: tuple[str | int, ...]) -> None:
        path = self.listed(name, where)
        if path is None:
            return
        doc = source.load(path, self.sink)
        if doc is None:
            return
        self.doc = doc
        if not isinstance(doc.data, dict):
            self.error((), "E0512", "a SMURF annotation file is a mapping from a category "
                       "(motors, sensors, …) to its content")
            return
        for category, content in doc.data.items():
            if category == "_autogenerated":  # Phobos's mark_as_autogenerated
                continue
            # Phobos reads a singular category (`motor:`) as its plural, for old files.
            kind = f"{category}s" if f"{category}s" in _LISTS and f"{category}s" not in doc.data else category
            if kind == "submodels" and isinstance(content, dict):
                self.state.submodels.update(content)  # definitions, by name (Phobos's keys)
            elif kind in _LISTS:
                handler = getattr(self, f"_{kind}")
                for i, entry in self.entries(category, content):
                    handler(entry, (category, i))
            elif isinstance(content, dict | list):
                # Free categories, and Phobos's `interfaces`, are kept as they are.
                self.state.annotations[category] = content  # type: ignore[assignment]
            else:
                self.error((category,), "E0512", f"annotation category '{category}' is a mapping "
                           "or a list (mpc keeps free annotations as they are)")

    def entries(self, category: str, content: Any) -> Iterator[tuple[int, dict[str, Any]]]:
        """The entries of a list category, each a mapping with a string `name`."""
        if not isinstance(content, list):
            self.error((category,), "E0512", f"'{category}' is a list of entries")
            return
        for i, entry in enumerate(content):
            if not isinstance(entry, dict) or not isinstance(entry.get("name"), str):
                self.error((category, i), "E0512", f"each entry of '{category}' is a mapping with a "
                           "'name'")
                continue
            yield i, dict(entry)

    def known(self, kind: str, name: Any, pool: Any, where: tuple[str | int, ...]) -> bool:
        if isinstance(name, str) and name in pool:
            return True
        entry = self.doc.data_at((*where[:2], "name"))
        self.error(where, "E0514", f"{where[0]} entry '{entry}': the model has no {kind} '{name}'"
                   + did_you_mean(str(name), set(pool)))
        return False

    # -- categories ------------------------------------------------------------------------

    def _motors(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        if not self.known("joint", e.get("joint"), s.joints, (*at, "joint")):
            return
        name, joint = e.pop("name"), e.pop("joint")
        for key, value in (*motor_limits(s.base, joint).items(), ("type", MOTOR_TYPE)):
            if e.get(key) == value:
                del e[key]
        s.motors[name] = Motor(name=name, joint=joint, settings=e)

    def _sensors(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        kind = e.get("type")
        if not isinstance(kind, str):
            self.error(at, "E0512", f"sensor '{e['name']}' has no 'type'")
            return
        for key, pool in (("link", s.links), ("joint", s.joints), ("frame", s.links)):
            if key in e and not self.known(key, e[key], pool, (*at, key)):
                return
        targets = e.get("targets", [])
        if not isinstance(targets, list) or not all(
                self.known("target", t, s.joints.keys() | s.links.keys(), (*at, "targets", i))
                for i, t in enumerate(targets)):
            return
        offsets = {}
        forms = (("position_offset", position_in, "3 numbers or a mapping x, y, z"),
                 ("orientation_offset", orientation_in, "3 numbers (rpy) or 4 (a quaternion x, y, z, w), "
                  "or a mapping r, p, y or x, y, z, w"))
        for key, parse, what in forms:
            if key in e:
                offsets[key] = parse(e[key])
                if offsets[key] is None:
                    self.error((*at, key), "E0512", f"'{key}' of sensor '{e['name']}' is {what}")
                    return
        # Phobos writes the offsets again as `origin` (position, rotation in rpy, relative_to).
        origin = e.get("origin")
        if isinstance(origin, dict) and not offsets:
            pairs = (("position_offset", "position", (3,)), ("orientation_offset", "rotation", (3, 4)))
            for key, field, sizes in pairs:
                value = floats(origin.get(field), sizes)
                if value is not None and any(value):
                    offsets[key] = value
        core = ("name", "type", "link", "joint", "frame", "targets", "position_offset", "orientation_offset",
                "origin")
        s.sensors[e["name"]] = Sensor(
            name=e["name"], type=kind, link=e.get("link"), joint=e.get("joint"), frame=e.get("frame"),
            targets=tuple(targets), annotations={k: v for k, v in e.items() if k not in core},
            **offsets)

    def _poses(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        values = e.get("joints", {})
        if not isinstance(values, dict) or not all(number(v) for v in values.values()):
            self.error((*at, "joints"), "E0512", f"'joints' of pose '{e['name']}' maps joint names "
                       "to numbers")
            return
        if all(self.known("joint", j, self.state.joints, (*at, "joints", j)) for j in values):
            self.state.poses[e["name"]] = {j: float(v) for j, v in values.items()}

    def _joints(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        name = e.pop("name")
        if e.get("cut_joint") is True:
            self.cut_joint(name, e, at)
            return
        if not self.known("joint", name, s.joints, (*at, "name")):
            return
        joint = s.joints[name]
        for key, field in _JOINT_CHECKED:
            if key in e and e[key] != getattr(joint, field):
                self.sink.warning(self.doc.value_span((*at, key)), "W0620", f"joints entry '{name}' says "
                                  f"{key} '{e[key]}', the model file '{getattr(joint, field)}'; the model "
                                  "file's is kept (as Phobos does)")
            e.pop(key, None)
        for key in _JOINT_DERIVED:
            e.pop(key, None)
        if e.get("cut_joint") is False:
            del e["cut_joint"]
        if e.get("constraint_axes") == []:
            del e["constraint_axes"]
        s.joints[name] = replace(joint, annotations={**joint.annotations, **e})

    def cut_joint(self, name: str, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        if not all(self.known("link", e.get(k), s.links, (*at, k)) for k in ("parent", "child")):
            return
        origin = e.get("origin", {})
        # mpc writes xyz and rpy; Phobos's Pose position and rotation (rpy).
        xyz = rpy = None
        if isinstance(origin, dict):
            xyz = floats(origin.get("xyz", origin.get("position", [0, 0, 0])), (3,))
            rpy = floats(origin.get("rpy", origin.get("rotation", [0, 0, 0])), (3,))
        axes = []
        for i, a in enumerate(e.get("constraint_axes", [])):
            axis = floats(a.get("axis"), (3,)) if isinstance(a, dict) else None
            if axis is None:
                self.error((*at, "constraint_axes", i), "E0512", f"a constraint axis of cut joint "
                           f"'{name}' is a mapping with an 'axis' of 3 numbers")
                return
            axes.append((a.get("name"), axis))
        if xyz is None or rpy is None:
            self.error((*at, "origin"), "E0512", f"'origin' of cut joint '{name}' has 'xyz' and 'rpy', "
                       "3 numbers each")
            return
        core = ("cut_joint", "joint_type", "parent", "child", "origin", "constraint_axes")
        s.cut_joints[name] = CutJoint(
            name=name, type=str(e.get("joint_type", "fixed")), parent=e["parent"], child=e["child"],
            origin=Pose(xyz, rpy), constraint_axes=tuple(axes),  # type: ignore[arg-type]
            annotations={k: v for k, v in e.items() if k not in core})

    def _links(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        name = e.pop("name")
        if self.known("link", name, s.links, (*at, "name")):
            for key in ("collisions", "visuals"):  # its shapes' names: the model file has them
                e.pop(key, None)
            s.links[name] = replace(s.links[name], annotations={**s.links[name].annotations, **e})

    def _materials(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        s = self.state
        name = e.pop("name")
        if name == "None" and not e and name not in s.materials:
            self.sink.warning(self.doc.value_span(at), "W0621", "materials entry 'None' names no material "
                              "(Phobos writes it for visuals without one); it is left out")
            return
        old = s.materials.get(name) or Material(name=name, span=self.doc.value_span(at))
        changes: dict[str, Any] = {}
        for field, key in (("rgba", "diffuseColor"), *MATERIAL_COLOURS):
            if key in e:
                values = colour_in(e.pop(key), (4,) if field == "rgba" else (3, 4))
                if values is None:
                    self.error((*at, key), "E0512", f"'{key}' of material '{name}' is r, g, b"
                               f"{', a' if field == 'rgba' else ' (and a)'}: numbers, as a mapping or a list")
                    return
                changes[field] = values
        for key in MATERIAL_SCALARS:
            if key in e:
                changes[key] = e.pop(key)
        rgba = changes.get("rgba", old.rgba)
        # Phobos writes transparency = 1 - alpha for every coloured material.
        if rgba is not None and old.transparency is None and changes.get("transparency") == 1.0 - rgba[3]:
            del changes["transparency"]
        s.materials[name] = replace(old, **changes, annotations={**old.annotations, **e})

    def _collisions(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        self.shape("collision", e, at)

    def _visuals(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        self.shape("visual", e, at)

    def find_shape(self, kind: str, e: dict[str, Any], at: tuple[str | int, ...]) -> tuple[str, int] | None:
        """The link and place of the shape an entry names (by its name, Phobos's name for an
        unnamed one, or mpc's older `index`); None after reporting why."""
        s = self.state
        name, link_name = e["name"], e.get("link")
        if link_name is not None and not self.known("link", link_name, s.links, (*at, "link")):
            return None
        index = e.get("index")
        if link_name is not None and isinstance(index, int) and not isinstance(index, bool):
            shapes = getattr(s.links[link_name], f"{kind}s")
            # mpc before Phobos's names wrote an unnamed shape as `<link>_<kind>` and its place.
            if 0 <= index < len(shapes) and name == f"{link_name}_{kind}" and \
                    shapes[index].name in (None, name, f"{name}_{index}"):
                return link_name, index
        for candidate in [link_name] if link_name is not None else sorted(s.links):
            shapes = getattr(s.links[candidate], f"{kind}s")
            names = shape_names(candidate, kind, [c.name for c in shapes])
            for i, shape in enumerate(shapes):
                if name in (shape.name, names[i]):
                    return candidate, i
        where = f" of link '{link_name}'" if link_name is not None else " in the model"
        self.error((*at, "name"), "E0514", f"{kind}s entry '{name}' names no {kind}{where}")
        return None

    def shape(self, kind: str, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        """Annotations (and a collision's bitmask) of the shape an entry names: in its `link`
        when it gives one, else wherever the model has it (Phobos lists shapes by name)."""
        found = self.find_shape(kind, e, at)
        if found is None:
            return
        link_name, index = found
        name = e.pop("name")
        e.pop("index", None)
        for key in _SHAPE_DERIVED:
            e.pop(key, None)
        link = self.state.links[link_name]
        shapes = list(getattr(link, f"{kind}s"))
        changes: dict[str, Any] = {}
        if kind == "collision" and "bitmask" in e:
            bitmask = e.pop("bitmask")
            if not isinstance(bitmask, int) or isinstance(bitmask, bool) or bitmask < 0:
                self.error((*at, "bitmask"), "E0512", f"'bitmask' of collision '{name}' is a "
                           "non-negative integer")
                return
            changes["bitmask"] = bitmask
        shape = shapes[index]
        shapes[index] = replace(shape, **changes, annotations={**shape.annotations, **e})
        self.state.links[link_name] = replace(link, **{f"{kind}s": tuple(shapes)})

    def _submechanisms(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        self.state.submechanisms.append(Submechanism(name=e["name"], definition=e))

    def _exoskeletons(self, e: dict[str, Any], at: tuple[str | int, ...]) -> None:
        self.state.submechanisms.append(Submechanism(name=e["name"], exoskeleton=True, definition=e))


_LISTS = ("motors", "sensors", "poses", "joints", "links", "materials", "collisions", "visuals",
          "submechanisms", "exoskeletons")


class _State:
    """The robot being completed, as mutable mappings (the value is built once at the end)."""

    def __init__(self, robot: Robot) -> None:
        self.base = robot
        self.links, self.joints = dict(robot.links), dict(robot.joints)
        self.materials = dict(robot.materials)
        self.motors, self.sensors = dict(robot.motors), dict(robot.sensors)
        self.cut_joints, self.poses = dict(robot.cut_joints), dict(robot.poses)
        self.submechanisms: list[Submechanism] = list(robot.submechanisms)
        self.annotations = dict(robot.annotations)
        self.submodels: dict[str, Any] = dict(robot.submodel_definitions)

    def robot(self) -> Robot:
        return replace(self.base, links=self.links, joints=self.joints, materials=self.materials,
                       motors=self.motors, sensors=self.sensors, cut_joints=self.cut_joints,
                       poses=self.poses, submechanisms=tuple(self.submechanisms),
                       annotations=self.annotations, submodel_definitions=self.submodels)


__all__ = ["MODEL_SUFFIXES", "read"]


def entry_span(path: Path, category: str, name: str) -> Span | None:
    """Where the SMURF at `path` (read before, without errors) names the entry `name` of a list
    `category` (`poses`, `motors`, …) in one of its annotation files; None when none does."""
    quiet = Sink()
    smurf = source.load(path, quiet)
    files = smurf.data.get("files") if smurf is not None and isinstance(smurf.data, dict) else None
    for listed in files if isinstance(files, list) else ():
        if not isinstance(listed, str) or Path(listed).suffix.lower() in MODEL_SUFFIXES:
            continue
        doc = source.load(path.parent / listed, quiet)
        content = doc.data.get(category) if doc is not None and isinstance(doc.data, dict) else None
        for i, entry in enumerate(content if isinstance(content, list) else ()):
            if isinstance(entry, dict) and entry.get("name") == name:
                return doc.value_span((category, i, "name"))
    return None
