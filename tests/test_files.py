"""Every output goes through one writer: whole or not at all, on disk before the rename, with the
permissions a plain open() would give (from the umask), figures included."""

import os
import stat

import pandas as pd
import pytest

from stcs_ident import files


@pytest.fixture
def umask_027():
    old = os.umask(0o027)
    yield 0o640
    os.umask(old)


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_text_csv_and_figures_get_the_mode_of_the_umask(tmp_path, umask_027):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    fig.subplots().plot([0, 1], [1, 0])
    files.write_atomic(tmp_path / "a.json", "{}\n")
    files.write_csv(pd.DataFrame({"x": [1.5, 2.0]}), tmp_path / "t.csv", index=False)
    files.write_figure(fig, tmp_path / "f.png")
    assert (tmp_path / "a.json").read_text() == "{}\n"
    assert (tmp_path / "t.csv").read_text() == "x\n1.5\n2.0\n"
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p.name: _mode(p) for p in tmp_path.iterdir()} == {"a.json": umask_027, "t.csv": umask_027,
                                                               "f.png": umask_027}


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="midway"), files.atomic_file(target) as stream:
        stream.write("new, half")
        raise RuntimeError("midway")
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_the_report_files_get_the_mode_of_the_umask(tmp_path, umask_027):
    from matplotlib.figure import Figure

    from stcs_ident.identify.tables import write_csv
    from stcs_ident.plots import save_figure

    class Result:  # only what write_csv reads
        def to_dataframe(self):
            return pd.DataFrame({"mode": [1], "measured_Hz": [1.0]})

    write_csv(Result(), tmp_path / "table.csv")
    save_figure(Figure(figsize=(1, 1)), tmp_path / "fig.png")
    assert _mode(tmp_path / "table.csv") == _mode(tmp_path / "fig.png") == umask_027
