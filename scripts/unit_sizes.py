#!/usr/bin/env python3
"""Function lengths in C++ sources, for issue 45 ("size of units").

Counts the lines of every function in the .cc and .h files under the given directories and
prints those longer than --over lines (default 100), longest first, then how many there were.

How a function is found (docs/measurements.md, "Size of units (issue 45)"):
- comments, string and character literals and preprocessor lines are blanked first, so their
  braces and parentheses do not count;
- at namespace or class scope, a `{` whose declaration holds a parameter list opens a function
  body (a constructor's member initialisers `a_{x}` are skipped); `namespace`, `class`,
  `struct`, `union`, `enum` and `extern` open scopes to look into; a `{` after `=` is an
  initialiser, not a function;
- a function's lines run from the first line of its signature (its template line included) to
  its closing brace; braces inside it, lambdas included, belong to it.

Tests, test utilities and benchmarks are left out unless --tests is given.

With --unused, it lists instead the functions of the given paths whose name is used in no
function body (its own definition aside) in src/, include/ or python/ (tests included, comments
and strings left out; every word of a Python file counts): candidates to check by hand, since
a constructor, an overload or a callback taken by address at namespace scope shows up too.

Usage: scripts/unit_sizes.py [--over N] [--tests] [--unused] DIR_OR_FILE...
"""

import argparse
import collections
import os
import re
import sys

SCOPE_KEYWORDS = re.compile(r'^(namespace|class|struct|union|enum|extern)\b')
CONTROL_KEYWORDS = {'if', 'for', 'while', 'switch', 'catch', 'return', 'sizeof', 'decltype',
                    'alignof', 'noexcept', 'static_assert'}
TEST_FILE = re.compile(r'(_test\.cc|_test_util\.h|_benchmark\.cc|_fuzz\.cc)$')


def blank_non_code(text):
    """The text with comments, literals and preprocessor lines turned into spaces.

    Newlines are kept so that positions still map to the same line numbers; a literal keeps
    its quotes so that `""` still separates tokens."""
    out = list(text)
    i, n = 0, len(text)
    at_line_start = True

    def blank(a, b):
        for k in range(a, b):
            if out[k] != '\n':
                out[k] = ' '

    while i < n:
        c = text[i]
        if c == '\n':
            at_line_start = True
            i += 1
            continue
        if at_line_start and c in ' \t':
            i += 1
            continue
        if at_line_start and c == '#':
            # A preprocessor line, with its backslash continuations.
            j = i
            while j < n and not (text[j] == '\n' and text[j - 1] != '\\'):
                j += 1
            blank(i, j)
            i = j
            continue
        at_line_start = False
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif c == 'R' and text.startswith('"', i + 1) and (i == 0 or not _word_char(text[i - 1])
                                                            or text[i - 1] in 'uU8L'):
            # A raw string: R"delim( ... )delim".
            open_paren = text.find('(', i + 2)
            delim = text[i + 2:open_paren]
            close = text.find(')' + delim + '"', open_paren)
            j = n if close < 0 else close + len(delim) + 2
            blank(i + 2, j - 1)
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and _word_char(text[i - 1]))):
            # A string or a character literal; a quote after a digit or letter is a digit
            # separator (1'000).
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            blank(i + 1, min(j, n))
            i = j + 1
        else:
            i += 1
    return ''.join(out)


def _word_char(c):
    return c.isalnum() or c == '_'


def matching_brace(code, open_at):
    depth = 0
    for k in range(open_at, len(code)):
        if code[k] == '{':
            depth += 1
        elif code[k] == '}':
            depth -= 1
            if depth == 0:
                return k
    return len(code) - 1


def strip_access_and_template(header):
    """The declaration without leading access specifiers and template parameter lists."""
    header = header.strip()
    while True:
        m = re.match(r'^(public|private|protected)\s*:(?!:)\s*', header)
        if m:
            header = header[m.end():]
            continue
        if header.startswith('template'):
            k = header.find('<')
            depth, j = 0, k
            while 0 <= j < len(header):
                depth += {'<': 1, '>': -1}.get(header[j], 0)
                if depth == 0:
                    break
                j += 1
            header = header[j + 1:].lstrip()
            continue
        m = re.match(r'^\[\[.*?\]\]\s*', header)
        if m:
            header = header[m.end():]
            continue
        return header


def has_top_level(header, char):
    depth = 0
    for k, c in enumerate(header):
        if c in '([<':
            depth += 1
        elif c in ')]>':
            depth -= 1
        elif c == char and depth <= 0:
            if char == ':' and (header[k - 1:k] == ':' or header[k + 1:k + 2] == ':'):
                continue
            return True
    return False


def function_name(header):
    """The qualified name before the parameter list: the first `name(` at paren depth 0."""
    depth = 0
    for k, c in enumerate(header):
        if c == '(':
            if depth == 0:
                m = re.search(r'((?:~?[A-Za-z_]\w*(?:<[^()]*?>)?::)*'
                              r'(?:operator\s*\S+?|~?[A-Za-z_]\w*))\s*$', header[:k])
                if m and m.group(1) not in CONTROL_KEYWORDS:
                    return re.sub(r'\s+', '', m.group(1))
            depth += 1
        elif c == ')':
            depth -= 1
    return '?'


def functions_in(code):
    """(name, first offset, closing-brace offset) of each function in the blanked code."""
    found = []

    def scan(start, end):
        header_start = start
        parens = 0  # Open parentheses of the declaration being read.
        k = start
        while k < end:
            c = code[k]
            if c in '()':
                parens += 1 if c == '(' else -1
                k += 1
                continue
            if c == '{' and parens > 0:
                # A brace inside a parameter list or initialiser (`= {}`, a lambda member
                # initialiser): part of the declaration.
                k = matching_brace(code, k) + 1
                continue
            if c in ';}':
                header_start = k + 1
                parens = 0
                k += 1
                continue
            if c == ':' and re.match(r'(public|private|protected)\s*$',
                                     code[header_start:k].strip()):
                header_start = k + 1
                k += 1
                continue
            if c != '{':
                k += 1
                continue
            header = code[header_start:k]
            bare = strip_access_and_template(header)
            close = matching_brace(code, k)
            if SCOPE_KEYWORDS.match(bare) and not re.match(r'^(class|struct|enum)\b[^(]*\(',
                                                           bare):
                scan(k + 1, close)
            elif '(' in bare and not has_top_level(bare, '='):
                before = code[header_start:k].rstrip()
                in_initialisers = has_top_level(bare[bare.find(')'):], ':') \
                    if ')' in bare else False
                if in_initialisers and before and (_word_char(before[-1]) or before[-1] == '>'):
                    # A member initialiser `a_{x}` in a constructor's list: part of the header.
                    k = close + 1
                    continue
                first = header_start + len(header) - len(header.lstrip())
                found.append((function_name(bare), first, close))
            header_start = close + 1
            parens = 0
            k = close + 1

    scan(0, len(code))
    return found


def line_of(text, offset, line_starts):
    lo, hi = 0, len(line_starts)
    while lo + 1 < hi:
        mid = (lo + hi) // 2
        if line_starts[mid] <= offset:
            lo = mid
        else:
            hi = mid
    return lo + 1


def source_files(paths, with_tests):
    for path in paths:
        if os.path.isfile(path):
            yield path
            continue
        for root, _, files in os.walk(path):
            for name in sorted(files):
                if not name.endswith(('.cc', '.h')):
                    continue
                if not with_tests and (TEST_FILE.search(name) or 'testing' in name):
                    continue
                yield os.path.join(root, name)


def measure(path):
    with open(path, encoding='utf-8', errors='replace') as f:
        text = f.read()
    code = blank_non_code(text)
    line_starts = [0] + [m.end() for m in re.finditer('\n', text)]
    for name, first, close in functions_in(code):
        a = line_of(text, first, line_starts)
        b = line_of(text, close, line_starts)
        yield name, a, b - a + 1


def names_used(roots=('src', 'include', 'python')):
    """How often each word stands in a function body of the C++ files under `roots` (the name of
    the function being defined not counted) or anywhere in their Python files."""
    uses = collections.Counter()
    for root_dir in roots:
        for root, _, files in os.walk(root_dir):
            for name in files:
                path = os.path.join(root, name)
                if name.endswith(('.py', '.pyi')):
                    with open(path, encoding='utf-8', errors='replace') as f:
                        uses.update(re.findall(r'[A-Za-z_]\w*', f.read()))
                    continue
                if not name.endswith(('.cc', '.h', '.cpp', '.hpp')):
                    continue
                with open(path, encoding='utf-8', errors='replace') as f:
                    code = blank_non_code(f.read())
                for function, first, close in functions_in(code):
                    words = collections.Counter(re.findall(r'[A-Za-z_]\w*', code[first:close + 1]))
                    own = function.split('::')[-1]
                    if words[own]:
                        words[own] -= 1
                    uses.update(words)
    return uses


def print_unused(paths, with_tests):
    uses = names_used()
    unused = 0
    for path in source_files(paths, with_tests):
        with open(path, encoding='utf-8', errors='replace') as f:
            code = blank_non_code(f.read())
        line_starts = [0] + [m.end() for m in re.finditer('\n', code)]
        for function, first, _ in functions_in(code):
            own = function.split('::')[-1]
            if own.startswith(('~', 'operator')) or own == '?' or uses[own]:
                continue
            unused += 1
            print(f'{path}:{line_of(code, first, line_starts)}  {function}')
    print(f'{unused} functions whose name no function body uses')


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('paths', nargs='+', help='directories or files')
    parser.add_argument('--over', type=int, default=100,
                        help='print functions longer than this many lines (default 100)')
    parser.add_argument('--tests', action='store_true',
                        help='include tests, test utilities and benchmarks')
    parser.add_argument('--longest', type=int, default=0,
                        help='also print the N longest functions')
    parser.add_argument('--unused', action='store_true',
                        help='list the functions whose name no function body uses (run from the '
                             'repository\'s root)')
    args = parser.parse_args()
    if args.unused:
        print_unused(args.paths, args.tests)
        return 0
    rows = []
    for path in source_files(args.paths, args.tests):
        for name, line, length in measure(path):
            rows.append((length, path, line, name))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    over = [r for r in rows if r[0] > args.over]
    for length, path, line, name in over:
        print(f'{length:5d}  {path}:{line}  {name}')
    if args.longest:
        print(f'longest {args.longest}:')
        for length, path, line, name in rows[:args.longest]:
            print(f'{length:5d}  {path}:{line}  {name}')
    print(f'{len(over)} functions over {args.over} lines '
          f'(of {len(rows)} functions in {len({r[1] for r in rows})} files)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
