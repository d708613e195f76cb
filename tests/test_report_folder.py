"""A report folder written again holds the new report only: files the last report wrote and
this one does not are removed (they would show stale results beside it); files of others stay,
and a report that fails changes nothing."""

import pytest

from fixplan.io.report_document import MANIFEST, staged_folder


def _report(folder, files: dict) -> None:
    with staged_folder(folder) as staging:
        for name, text in files.items():
            (staging / name).write_text(text, encoding="utf-8")


def _files(folder) -> dict:
    return {p.name: p.read_text(encoding="utf-8") for p in folder.iterdir() if p.is_file()}


def test_a_report_written_again_removes_what_the_last_one_wrote_and_this_one_does_not(tmp_path):
    folder = tmp_path / "report"
    _report(folder, {"report.md": "first\n", "layout-1.png": "1", "layout-2.png": "2"})
    (folder / "notes.txt").write_text("mine\n", encoding="utf-8")
    _report(folder, {"report.md": "second\n", "layout-1.png": "1'"})
    assert _files(folder) == {"report.md": "second\n", "layout-1.png": "1'",
                              "notes.txt": "mine\n", MANIFEST: "layout-1.png\nreport.md\n"}  # fmt: skip


def test_only_plain_names_of_files_in_the_folder_are_removed(tmp_path):
    folder, outside = tmp_path / "report", tmp_path / "outside.txt"
    folder.mkdir()
    outside.write_text("elsewhere\n", encoding="utf-8")
    (folder / "kept").mkdir()
    (folder / MANIFEST).write_text("../outside.txt\nkept\n.\n..\n\n", encoding="utf-8")
    _report(folder, {"report.md": "new\n"})
    assert outside.exists() and (folder / "kept").is_dir()


def test_a_report_that_fails_leaves_the_folder_as_it_was(tmp_path):
    folder = tmp_path / "report"
    _report(folder, {"report.md": "first\n", "figure.png": "f"})
    before = _files(folder)
    with pytest.raises(RuntimeError), staged_folder(folder) as staging:
        (staging / "report.md").write_text("half\n", encoding="utf-8")
        raise RuntimeError("a figure failed")
    assert _files(folder) == before
    assert [p.name for p in tmp_path.iterdir()] == ["report"]  # (no staging folder left)


def test_a_manifest_of_odd_names_or_a_folder_of_its_name_does_not_stop_a_report(tmp_path):
    folder = tmp_path / "report"
    folder.mkdir()
    (folder / MANIFEST).write_text("x" * 300 + "\nreport.md\n", encoding="utf-8")  # (too long)
    _report(folder, {"report.md": "new\n"})
    assert (folder / "report.md").read_text(encoding="utf-8") == "new\n"
    other = tmp_path / "other"
    (other / MANIFEST).mkdir(parents=True)
    _report(other, {"report.md": "new\n"})
    assert (other / "report.md").is_file() and (other / MANIFEST).is_dir()
