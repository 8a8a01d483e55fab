#!/usr/bin/env python3
"""docs/ARCHITECTURE.md's worked example of adding a study is the code tests/core/study_example_test.cpp
compiles and runs: the page's cpp block after the line "<!-- example: tests/core/study_example_test.cpp -->"
must equal the text between the file's markers. usage: architecture_example.py SOURCE_DIR"""
import sys
from pathlib import Path

src = Path(sys.argv[1])
code = (src / "tests/core/study_example_test.cpp").read_text().split("\n")
start = code.index("// [architecture example]") + 1
end = code.index("// [end of architecture example]")
example = "\n".join(code[start:end]).strip("\n")
page = (src / "docs/ARCHITECTURE.md").read_text().split("\n")
marker = "<!-- example: tests/core/study_example_test.cpp -->"
if marker not in page:
    sys.exit(f"docs/ARCHITECTURE.md: no line {marker!r} before the worked example")
at = page.index(marker) + 1
if page[at] != "```cpp":
    sys.exit(f"docs/ARCHITECTURE.md:{at + 1}: expected ```cpp after the marker")
close = page.index("```", at + 1)
shown = "\n".join(page[at + 1:close]).strip("\n")
if shown != example:
    import difflib
    diff = "\n".join(difflib.unified_diff(example.split("\n"), shown.split("\n"), "tests/core/study_example_test.cpp",
                                          "docs/ARCHITECTURE.md", lineterm=""))
    sys.exit("docs/ARCHITECTURE.md's worked example differs from the code that is compiled and run:\n" + diff)
print(f"docs/ARCHITECTURE.md:{at + 1}: the worked example is the code tests/core/study_example_test.cpp runs "
      f"({close - at - 1} lines)")
