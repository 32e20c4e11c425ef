"""One line per fact (issue 37's item 4, the skipped tests): tests skipped for one reason are one line naming
them, in stdout and in the report (han2020 printed nine "Skipped case…" lines in each, and nine more notes)."""

from stcs_ident.report.diagnose import skipped_lines


def test_skipped_tests_are_one_line_per_reason():
    skipped = [(f"case{c}-L{level}", "no measured frequencies and no record") for c in (1, 2, 3) for level in (1, 2, 3)]
    skipped.append(("T9", "its record is unreadable"))
    lines = skipped_lines(skipped)
    assert lines == [("9 tests (no measured frequencies and no record): case1-L1, case1-L2, case1-L3, case2-L1, "
                     "case2-L2, case2-L3, case3-L1, case3-L2, case3-L3"),
                     "T9: its record is unreadable"]
    assert skipped_lines([]) == []
