"""The formats' tables agree: the schema's export entries (compiler/schema/exports.py), the
compiler's `LOWERING` (compiler/lower_exports.py), the formats' descriptors (backends/formats.py)
and the IR's export records. A format added to one and not the others fails here."""

from __future__ import annotations

import subprocess
import sys
import typing
from pathlib import Path

import pytest

from mpc.backends.formats import FORMATS, reader_of
from mpc.compiler.lower_exports import LOWERING
from mpc.compiler.schema.exports import ExportEntry, SubmodelExport
from mpc.ir import program


def _type_of(node: type) -> str:
    """The `type` of a schema node or an IR record: its one Literal value."""
    (literal,) = typing.get_args(typing.get_type_hints(node)["type"])
    return literal


def _bare(hint: object) -> object:
    while typing.get_origin(hint) is typing.Annotated:
        hint = typing.get_args(hint)[0]
    return hint


def _union_members(union: object) -> list[type]:
    return [_bare(member) for member in typing.get_args(_bare(union))]  # type: ignore[misc]


def test_every_export_entry_of_the_schema_is_lowered_by_its_own_table_entry() -> None:
    nodes = {_type_of(node): node for node in _union_members(ExportEntry) if node is not SubmodelExport}
    assert nodes == {name: lowering.schema for name, lowering in LOWERING.items()}


def test_every_lowered_export_has_a_descriptor_naming_its_record_and_writer() -> None:
    for name in LOWERING:
        fmt = FORMATS[name]
        assert fmt.record is not None and _type_of(fmt.record) == name, name
        assert fmt.write is not None, name


def test_every_ir_export_record_has_one_descriptor() -> None:
    records = set(typing.get_args(program.Export))
    assert {f.record for f in FORMATS.values()} == records
    assert all(FORMATS[_type_of(record)].record is record for record in records)


def test_the_number_keys_of_a_format_are_named_for_its_errors() -> None:
    for fmt in FORMATS.values():
        assert bool(fmt.float_keys) == bool(fmt.numbers), fmt.name


@pytest.mark.parametrize(("name", "format_name"), [
    ("a.urdf", "urdf"), ("a.URDF", "urdf"), ("a.sdf", "sdf"), ("a.smurf", "smurf"), ("a.xml", "mjcf"),
    ("a", "urdf")])
def test_an_input_file_is_read_by_the_format_of_its_suffix(name: str, format_name: str) -> None:
    assert reader_of(Path(name)).name == format_name


def test_the_table_loads_no_backend() -> None:
    """`mpc check` reads the table (lowering asks it) and must not pay for a writer's libraries."""
    code = ("import sys, mpc.backends.formats, mpc.compiler.lower_exports; "
            "print(sorted(m for m in sys.modules if m.startswith('mpc.backends.') or m in "
            "('numpy', 'scipy', 'trimesh', 'lxml')))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "['mpc.backends.formats']"


def test_the_formats_that_leave_things_out_name_their_tables() -> None:
    """W0500's tables (backends/holds.py) are the descriptors' `holds`."""
    from mpc.backends import mjcf, sdf, usd

    assert {name: fmt.holds() for name, fmt in FORMATS.items() if fmt.holds is not None} == {
        "mjcf": mjcf.CANNOT_HOLD, "sdf": sdf.CANNOT_HOLD, "usd": usd.CANNOT_HOLD}
