"""Lower-bound files: nothing is silently dropped (unknown keys, one error given twice) and every
bound is a small angular error."""

import pytest

from turntable_pin.allocation.capability import ManufacturingCapability
from turntable_pin.core.exceptions import InputError


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("lower_bounds:\n  dphi_y1: 1\nreasonning:\n  dphi_y1: x\n",
         "unknown top-level key(s) 'reasonning'; the file holds 'lower_bounds:' and optionally "
         "'reasoning:'"),
        ("lower_bounds:\n  dphi_y1: 1\n  dphi_y1_arcmin: 0.1\n",
         "lower_bounds: 'dphi_y1_arcmin' and 'dphi_y1' both give dphi_y1"),
        ("lower_bounds:\n  dphi_y1: 1\n  dphi_y1: 2\n", "line 3: key 'dphi_y1' is given twice"),
        ("lower_bounds:\n  dphi_y1: 1\nreasoning:\n  dphi_y9: text\n",
         "reasoning: 'dphi_y9' is not an angular error"),
        ("lower_bounds:\n  dphi_y1: 1\nreasoning:\n  dphi_y1: [a, b]\n",
         "reasoning: 'dphi_y1' must be text"),
        ("lower_bounds:\n  deps_x_deg: 6\n", "is not a small error"),
        ("lower_bounds:\n  deps_x: 1e308\n", "is not a small error"),
    ],
)  # fmt: skip
def test_refused_files(tmp_path, text, fragment):
    path = tmp_path / "lb.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        ManufacturingCapability.from_yaml(path)
    assert fragment in str(info.value) and str(info.value).startswith(str(path))


def test_the_bundled_file_still_reads():
    capability = ManufacturingCapability.default()
    assert capability.lower_bounds_rad.max() > 0 and len(capability.reasoning) == 8
