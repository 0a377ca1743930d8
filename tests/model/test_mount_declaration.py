"""What a table says it is: the URDF's ``<turntable_pin mount="..."/>``, read by the table and
ignored by Pinocchio and yourdfpy; the caller's word over it; refusals naming the file."""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

from conftest import REPO_DIR
from turntable_pin.core.exceptions import InputError
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.mount_declaration import (
    ALTAZ,
    EQUATORIAL,
    NO_MOUNT,
    declaration_text,
    read_mount_declaration,
    resolve_mount,
)
from turntable_pin.model.paper_table import table_of

MODELS = REPO_DIR / "models"
MOUNTS = {ALTAZ: MODELS / "altaz_mount.urdf", EQUATORIAL: MODELS / "german_equatorial_mount.urdf"}
ZY_TURNTABLE = Path(__file__).resolve().parents[1] / "zy_turntable.urdf"
_ELEMENT = re.compile(r"^\s*<turntable_pin [^>]*/>\n", re.M)


def _declared(text: str, declaration: str) -> str:
    """``text`` with ``declaration`` as the first child of ``<robot>``."""
    head, tag, rest = re.split(r"(<robot [^>]*>\n)", text, maxsplit=1)
    return f"{head}{tag}  {declaration}\n{rest}"


def _write(folder: Path, text: str, name: str = "table.urdf") -> Path:
    path = folder / name
    path.write_text(text)
    return path


# --- Pinocchio and yourdfpy read the declared URDFs unchanged ------------------------------------


def _pinocchio_summary(model) -> tuple:
    placements = [m.homogeneous for m in model.jointPlacements]
    return tuple(model.names), model.nq, [f.name for f in model.frames], np.array(placements)


@pytest.mark.parametrize("kind", [ALTAZ, EQUATORIAL])
def test_pinocchio_and_yourdfpy_ignore_the_declaration(tmp_path, kind):
    # pin 4 here (CI also runs the floor, pin 3.3.1, whose urdfdom skips unknown children too).
    declared = MOUNTS[kind].read_text()
    assert len(_ELEMENT.findall(declared)) == 1
    bare = _ELEMENT.sub("", declared)
    a, b = pin.buildModelFromXML(declared), pin.buildModelFromXML(bare)
    c = pin.buildModelFromUrdf(str(MOUNTS[kind]))
    for model in (a, c):
        names, nq, frames, placements = _pinocchio_summary(model)
        assert (names, nq, frames) == _pinocchio_summary(b)[:3]
        np.testing.assert_array_equal(placements, _pinocchio_summary(b)[3])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = [
            yourdfpy.URDF.load(str(p), load_meshes=False, build_collision_scene_graph=False)
            for p in (MOUNTS[kind], _write(tmp_path, bare))
        ]
    assert sorted(loaded[0].joint_map) == sorted(loaded[1].joint_map)
    for name, joint in loaded[0].joint_map.items():
        np.testing.assert_array_equal(joint.origin, loaded[1].joint_map[name].origin)
    assert loaded[0].validate()


# --- what a table is ------------------------------------------------------------------------------


def test_bundled_mounts_declare_their_kind_and_other_tables_nothing():
    for kind, path in MOUNTS.items():
        table = GenericTable(path)
        assert table.declared_mount == table.telescope_mount == kind
    for name in ("turntable", "two_axis_vertical_outer", "three_axis_imu_table",
                 "single_axis_rate_table"):  # fmt: skip
        table = table_of(MODELS / f"{name}.urdf")
        assert table.declared_mount is None and table.telescope_mount is None
    assert GenericTable(ZY_TURNTABLE).telescope_mount is None  # a mount's axes, no declaration


def test_the_caller_s_word_overrides_the_urdf():
    assert GenericTable(ZY_TURNTABLE, telescope_mount=ALTAZ).telescope_mount == ALTAZ
    table = GenericTable(MOUNTS[ALTAZ], telescope_mount=NO_MOUNT)
    assert (table.declared_mount, table.telescope_mount) == (ALTAZ, None)
    assert table_of(telescope_mount=ALTAZ).telescope_mount == ALTAZ  # the paper's table too
    assert table_of().telescope_mount is None
    with pytest.raises(InputError, match="telescope_mount 'alt-az': expected altaz, equatorial"):
        GenericTable(ZY_TURNTABLE, telescope_mount="alt-az")
    assert resolve_mount(EQUATORIAL, None) == EQUATORIAL
    assert resolve_mount(EQUATORIAL, NO_MOUNT) is None


def test_import_tpoint_s_urdf_copies_declare_the_mount(tmp_path):
    from turntable_pin.measurement.tpoint import mount_urdf_text

    for kind, latitude in ((ALTAZ, None), (EQUATORIAL, 31.7)):
        path = _write(tmp_path, mount_urdf_text(kind, latitude), f"{kind}.urdf")
        assert GenericTable(path).telescope_mount == kind


@pytest.mark.parametrize(
    "declaration, message",
    [
        ('<turntable_pin mount="alt-az"/>', 'mount="alt-az"/>: expected one <turntable_pin mount'),
        ('<turntable_pin kind="altaz"/>', 'kind="altaz"/>: expected one'),
        ('<turntable_pin mount="altaz" lat="30"/>', "expected one"),
        ("<turntable_pin/>", "<turntable_pin />: expected one"),
        ('<turntable_pin mount="altaz"/><turntable_pin mount="altaz"/>', "twice"),
        ('<link name="x"><turntable_pin mount="altaz"/></link>', "inside another element"),
    ],
)
def test_a_malformed_declaration_is_refused_naming_the_file(tmp_path, declaration, message):
    path = _write(tmp_path, _declared(ZY_TURNTABLE.read_text(), declaration))
    with pytest.raises(InputError, match=re.escape(message)) as caught:
        GenericTable(path)
    assert caught.value.path == str(path)


def test_the_declaration_is_written_as_documented():
    assert declaration_text(ALTAZ) == '<turntable_pin mount="altaz"/>'
    root = ET.fromstring(_declared(ZY_TURNTABLE.read_text(), declaration_text(EQUATORIAL)))
    assert read_mount_declaration(root, "x.urdf") == EQUATORIAL
