"""The shot tables are read with the csv module (start-up, issue 14), as pandas read them before.

The reference is pandas itself (``read_csv(comment="#", dtype=str, keep_default_na=False)``, the
call this replaced): the same columns and the same text in every cell, for every bundled CSV and
for hand-made files with comments, blank lines, quotes, short rows and repeated column names.
Exact equality: both return the text of the file.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from semianalytic.errors import InputError
from semianalytic.penetration.validation import read_csv_rows

ROOT = Path(__file__).resolve().parent.parent

TRICKY = {
    "comments": "# a comment\n# another\na,b,c\n1,2,3\n# between rows\n4,5,6 # after a value\n\n7,8,9\n",
    "quotes": 'name,text,v\nx,"a, b",1\ny,"say ""hi""",2\nz,"# not a comment",3\n',
    "short_rows": "a,b,c\n1,2\n3,,\n,,\n4,5,6\n",
    "spaces": "a, b ,c\n 1 ,2, 3\n   \n4,5,6\n",
    "repeated_names": "a,b,a,a\n1,2,3,4\n",
    "bom": "\ufeffa,b\n1,2\n",
    "crlf": "a,b\r\n1,2\r\n\r\n3,4\r\n",
}


def _pandas(path: Path) -> tuple[list[str], list[dict]]:
    pd = pytest.importorskip("pandas")
    df = pd.read_csv(path, comment="#", dtype=str, keep_default_na=False)
    rows = [{c: ("" if not isinstance(v, str) else v) for c, v in row.items()} for _, row in df.iterrows()]
    return list(df.columns), rows


def test_every_bundled_csv_reads_as_with_pandas():
    paths = sorted((ROOT / "cases").glob("*.csv"))
    assert paths
    for path in paths:
        assert read_csv_rows(path) == _pandas(path), path.name


@pytest.mark.parametrize("name", sorted(TRICKY))
def test_hand_made_csv_reads_as_with_pandas(tmp_path, name):
    path = tmp_path / f"{name}.csv"
    path.write_bytes(TRICKY[name].encode())
    assert read_csv_rows(path) == _pandas(path)


@pytest.mark.parametrize("text", ["", "# only a comment\n\n", "a,b\n1,2,3\n", "\xff\xfe\x00bad"])
def test_unreadable_csv_is_bad_input(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(InputError) as exc:
        read_csv_rows(path)
    assert exc.value.field == "data.file" and "bad.csv" in exc.value.message
