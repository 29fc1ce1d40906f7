"""docs/bad-inputs.md, one section per kind of input, each section the table of one test's cases.

A test that tries bad inputs adds a row per case to its Section (what was tried, how it was
refused, the first line of the message) and calls `finish` at the end: the section in the document
must then hold exactly these rows, so the document cannot go stale. With MANISOFT_WRITE_TABLE=1 in
the environment `finish` rewrites the section from this run instead (the other sections are kept).
"""
import os
import re

DOCUMENT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "bad-inputs.md")

HEAD = """# Bad inputs and what ManiSoft says

Each section below lists bad inputs of one kind, tried as a user would send them, and the first line
of what the program or the Python module answers. Every row is produced by the test named in its
section, which fails when the program no longer answers as the row says; rerun that test with
`MANISOFT_WRITE_TABLE=1` in the environment to rewrite its section. In every case nothing that
looks like a complete output is left behind and nothing already written is changed (checked by the
same tests). DIR stands for the test's scratch folder.
"""


def cell(text, scratch=None):
    """A table cell: the scratch folder written DIR, '|' escaped, decimals cut to 6 places (the last
    digits of a divergence may differ between compilers)."""
    if scratch:
        text = text.replace(scratch, "DIR")
    return re.sub(r"(\d\.\d{6})\d+", r"\1", text.replace("|", "\\|"))


class Section:
    def __init__(self, title, intro, columns, keep=lambda row: False):
        """`keep(row)`: a documented row this run does not produce but keeps (the programs not
        built here)."""
        self.title, self.intro, self.columns, self.keep = title, intro, columns, keep
        self.rows = []

    def add(self, *cells):
        assert len(cells) == len(self.columns), cells
        self.rows.append("| " + " | ".join(cells) + " |")

    def _split(self, text):
        """(before, the section's rows, after) of the document's text."""
        start = text.find(f"\n## {self.title}\n")
        if start < 0:
            return text.rstrip("\n") + "\n", [], ""
        end = text.find("\n## ", start + 1)
        end = len(text) if end < 0 else end
        body = text[start:end]
        return text[:start + 1], [line for line in body.splitlines() if line.startswith("| ") and not line.startswith("| " + self.columns[0] + " |")], text[end + 1:]

    def finish(self, failures):
        """Checks the section against this run's rows (appends to `failures`), or rewrites it."""
        try:
            with open(DOCUMENT) as f:
                text = f.read()
        except OSError:
            text = HEAD
        before, documented, after = self._split(text)
        kept = [r for r in documented if r not in self.rows and self.keep(r)]
        if os.environ.get("MANISOFT_WRITE_TABLE") == "1":
            table = "\n".join([f"## {self.title}", "", self.intro.strip(), "", "| " + " | ".join(self.columns) + " |",
                               "|" + "---|" * len(self.columns)] + self.rows + kept)
            with open(DOCUMENT, "w") as f:
                f.write(before + table + "\n" + ("\n" + after if after else ""))
            print(f"-- wrote '{self.title}' in {DOCUMENT}: {len(self.rows)} rows from this run, {len(kept)} kept")
            return
        missing = [r for r in self.rows if r not in documented]
        stale = [r for r in documented if r not in self.rows and not self.keep(r)]
        if missing or stale:
            failures.append(f"{DOCUMENT}, section '{self.title}', does not match this run (rerun with MANISOFT_WRITE_TABLE=1):\n"
                            + "".join(f"  not in the table: {r}\n" for r in missing)
                            + "".join(f"  not answered any more: {r}\n" for r in stale))
