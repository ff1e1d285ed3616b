"""No function in src/ or include/ is longer than 80 lines (run by `make test`).

A function's length is the lines from its body's opening brace to its closing one, comments and blank
lines included: what a reader must hold at once. Lambdas and local classes count with the function
that holds them. A longer function is listed with its place and length; cut it where its steps are."""
import os
import re
import subprocess
import sys
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LIMIT = 80
CONTROL = re.compile(r"\b(if|for|while|switch|catch)\s*\(|\b(do|else|try)\s*$")


def without_comments_and_strings(text):
    """The text with comments and string and character literals emptied, its line breaks kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
            continue
        raw = re.match(r'R"([^(]{0,16})\(', text[i:i + 20])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            close = ")" + raw.group(1) + '"'
            j = text.find(close, i)
            j = n if j < 0 else j + len(close)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
            continue
        c = text[i]
        if c in "\"'" and not (c == "'" and i > 0 and text[i - 1].isdigit()):  # 1'000 is a digit separator
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out)


def function_lengths(text):
    """(length, first line, signature) of every function body outside another function's."""
    text = without_comments_and_strings(text)
    stack, found, line, context = [], [], 1, 0
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            head = " ".join(text[context:i].split())
            kind = "block"
            if not any(k == "function" for k, _, _ in stack):
                if re.search(r"\bnamespace\b", head) or head.startswith("extern"):
                    kind = "scope"
                elif re.search(r"\b(class|struct|union|enum)\b", head) and ")" not in head:
                    kind = "scope"
                elif ")" in head and not head.endswith("=") and not CONTROL.search(head):
                    kind = "function"
            stack.append((kind, line, head[-100:]))
            context = i + 1
        elif c == "}":
            if stack:
                kind, first, head = stack.pop()
                if kind == "function":
                    found.append((line - first + 1, first, head))
            context = i + 1
        elif c == ";":
            context = i + 1
    return found


class FunctionLength(unittest.TestCase):
    def test_the_measure(self):
        sample = ("namespace a {\nstruct S {\n  int f() const {\n    return 1;\n  }\n};\n"
                  "int g(int x) {\n  if (x) {\n    auto h = [](int y) {\n      return y;\n    };\n"
                  "  }\n  const char* s = \"}\";  // }\n  return x;\n}\n}  // namespace a\n")
        self.assertEqual([(n, first) for n, first, _ in function_lengths(sample)], [(3, 3), (9, 7)])

    def test_no_function_is_longer_than_the_limit(self):
        files = subprocess.check_output(["git", "ls-files", "src/*.cpp", "src/*.h", "include/*.h"], cwd=ROOT,
                                        universal_newlines=True).split()
        self.assertGreater(len(files), 200)
        longer, measured = [], 0
        for f in files:
            with open(os.path.join(ROOT, f), encoding="utf-8") as source:
                for length, first, head in function_lengths(source.read()):
                    measured += 1
                    if length > LIMIT:
                        longer.append("%s:%d: %d lines: %s" % (f, first, length, head))
        self.assertGreater(measured, 2000)
        self.assertEqual(longer, [], "functions over %d lines:\n%s" % (LIMIT, "\n".join(sorted(longer))))


if __name__ == "__main__":
    rosunit.unitrun("hrg_gyro", "source_function_length", FunctionLength, sys.argv)
