"""The location-bit format has one encode/decode pair (pddl_export.location_codec), and every reader uses it."""
from __future__ import annotations

import itertools
import re
from pathlib import Path

import numpy as np
import pytest

from pddl_export.lifted_rules import LiftedRules
from pddl_export.lifted_scene import CodeLayout, Piece
from pddl_export.location_codec import FIELD_BITS, FIELD_WIDTHS, LOCATION_BITS, UNSEEN, decode_location, \
    encode_location, field_widths
from pddl_export.symbolic import codes_from_bits

ROOT = Path(__file__).resolve().parents[1]
LEARNED = (0, 1, 0b10110010, (1 << 16) - 1)  # learned codes of 1 to 16 bits


def _all_fields(n_bits: int) -> list[tuple[int, ...]]:
    """Every value of every field of a format: 2**n_bits combinations."""
    return list(itertools.product(*(range(1 << w) for w in FIELD_WIDTHS[n_bits])))


@pytest.mark.parametrize("n_bits", LOCATION_BITS)
def test_every_field_value_round_trips_as_ints_and_arrays(n_bits):
    widths = field_widths(n_bits)
    assert sum(widths) == n_bits
    combos = _all_fields(n_bits)
    assert len(combos) == 1 << n_bits
    for learned in LEARNED:
        codes = set()
        for fields in combos:
            code = encode_location(learned, fields, n_bits)
            assert isinstance(code, int) and decode_location(code, n_bits) == (learned, fields)
            # the layout is the documented one: learned code, then the fields most significant first
            assert code >> n_bits == learned and format(code & ((1 << n_bits) - 1), f"0{n_bits}b") == \
                "".join(format(v, f"0{w}b") for v, w in zip(fields, widths))
            codes.add(code)
        assert len(codes) == len(combos)  # no two field values share a code
        columns = [np.array(c, np.int64) for c in zip(*combos)]
        arr = encode_location(np.full(len(combos), learned, np.int64), columns, n_bits)
        assert arr.shape == (len(combos),) and arr.tolist() == [encode_location(learned, f, n_bits) for f in combos]
        back_learned, back_fields = decode_location(arr, n_bits)
        assert back_learned.tolist() == [learned] * len(combos)
        assert [c.tolist() for c in back_fields] == [c.tolist() for c in columns]


def test_the_lifted_format_is_nine_bits_of_location_place_level():
    assert FIELD_BITS == 9 and FIELD_WIDTHS[FIELD_BITS] == (3, 3, 3) and UNSEEN == (1 << 3) - 1
    assert encode_location(5, (2, 0, 3)) == (5 << 9) | (2 << 6) | 3 == 2691
    assert decode_location(2691) == (5, (2, 0, 3))


@pytest.mark.parametrize("learned, fields, n_bits, message", [
    (0, (8, 0, 0), 9, "location field 0 8 does not lie in 0..7 (3 bits)"),
    (0, (0, 0, 9), 9, "location field 2 9 does not lie in 0..7 (3 bits)"),
    (0, (0, -1, 0), 9, "location field 1 -1 does not lie in 0..7 (3 bits)"),
    (0, (5, 2), 4, "location field 1 2 does not lie in 0..1 (1 bits)"),
    (-3, (0, 0, 0), 9, "learned code -3 does not lie 0 or more"),
    (0, (1, 2), 9, "the 9-bit location format has 3 fields, got 2"),
    (0, (1, 2), 8, "location bits must be one of (4, 5, 6, 7, 9), got 8"),
    (0, (np.array([1, 9]), np.array([0, 0]), np.array([0, 0])), 9, "location field 0 9 does not lie in 0..7"),
    (0, (np.array([1.0]), np.array([0]), np.array([0])), 9, "location field 0 must be integers, not float64"),
])
def test_a_field_that_does_not_fit_is_refused_in_one_line(learned, fields, n_bits, message):
    with pytest.raises(ValueError) as e:
        encode_location(learned, fields, n_bits)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_the_lifted_readers_decode_with_the_codec():
    """CodeLayout.piece, CodeLayout.learned and LiftedRules.code_of agree with the codec on every field value."""
    layout = CodeLayout(code_bits=8, kept=(0, 6))
    rules = LiftedRules(layout=layout, stick_of={}, rules=())
    for learned in (0, 0b10000010, 255):
        for loc, place, level in _all_fields(FIELD_BITS):
            code = encode_location(learned, (loc, place, level))
            p = layout.piece(code, stick=False)
            assert (p.loc, p.place, p.level, layout.learned(code)) == (loc, place, level, learned)
            assert rules.code_of(Piece(p.kind, False, loc, place, level), code) == code
    with pytest.raises(ValueError, match="location field 2 8 does not lie"):
        rules.code_of(Piece(0, False, 1, 0, 8), 0)  # a level past the field's 3 bits no longer spills into place


def test_location_bits_are_the_codec_s_fields():
    """symlearn.symbolic.locations writes its bits through the codec: decoded, they give the nearest location,
    the place and the height layer, and an unseen object all ones."""
    from symlearn.symbolic.locations import location_bits
    from symlearn.world import LOCATIONS, TABLE_TOP_Z

    xy = np.array([LOCATIONS[2], [LOCATIONS[3][0], LOCATIONS[3][1] + 0.10], [np.nan, np.nan]], np.float32)
    top = np.array([TABLE_TOP_Z + 0.10, TABLE_TOP_Z + 0.05, np.nan])
    code = codes_from_bits(location_bits(xy, 9, top))
    learned, (loc, place, level) = decode_location(code, 9)
    assert learned.tolist() == [0, 0, 0]
    assert loc.tolist() == [2, 3, UNSEEN] and place.tolist() == [0, 5, 7] and level.tolist() == [2, 1, 7]
    _, (loc4, off) = decode_location(codes_from_bits(location_bits(xy, 4)), 4)
    assert loc4.tolist() == [2, 3, UNSEEN] and off.tolist() == [0, 1, 1]


# A hand-written shift or mask of the location fields: `>> 6`, `>> 3`, `<< 9`, `& 7`, `& 511`, `>> FIELD_BITS`, ...
_HAND_WRITTEN = re.compile(r"(>>|<<)\s*(FIELD_BITS|[369])\b|&\s*(7|511|0x7|0x1ff|0o7|0b111)\b")


def _hand_written_shifts() -> list[str]:
    found = []
    for pkg in ("pddl_export", "symlearn", "search"):
        for f in sorted((ROOT / pkg).rglob("*.py")):
            if f.name == "location_codec.py":
                continue
            for n, line in enumerate(f.read_text().splitlines(), 1):
                code = line.split("#", 1)[0]
                if _HAND_WRITTEN.search(code):
                    found.append(f"{f.relative_to(ROOT)}:{n}: {line.strip()}")
    return found


def test_no_module_but_the_codec_shifts_the_location_fields_by_hand():
    assert _hand_written_shifts() == []


def test_the_shift_scan_sees_the_forms_it_looks_for():
    """The scan is not vacuous: each form the readers used before the codec is caught, and wider shifts are not."""
    for line in ("loc=(code >> 6) & 7", "level=code & 7", "(int(learned) << 9) | x", "objects >> FIELD_BITS",
                 "(c & 511)", "(field << 3) | height"):
        assert _HAND_WRITTEN.search(line), line
    for line in ("1 << 20", "x >> 62", "mb << 20", "(value >> bit) & 1", "1 << 63"):
        assert not _HAND_WRITTEN.search(line), line
