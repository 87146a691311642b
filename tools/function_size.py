#!/usr/bin/env python3
"""function_size.py MAX FILE... - functions (lambdas included) whose body spans more than MAX
lines, as clang-tidy's readability-function-size LineThreshold counts them: the line of the
closing brace minus the line of the opening one. Function extents come from universal-ctags."""
import json, subprocess, sys

def body_open(lines, start, end):
    # The opening brace of the body: the first '{' from the definition's line on that is not
    # inside the parameter list's parentheses (default arguments may hold braces).
    depth = 0
    for i in range(start - 1, end):
        for ch in lines[i]:
            if ch == '(':
                depth += 1
            elif ch == ')':
                depth -= 1
            elif ch == '{' and depth == 0:
                return i + 1
    return start

def run_ctags(files):
    """The ctags JSON lines of every function definition (lambdas included) in files."""
    return subprocess.run(['ctags', '--output-format=json', '--fields=+ne', '--kinds-C++=f',
                           '--language-force=C++', '-f', '-'] + files,
                          check=True, capture_output=True, text=True).stdout


def main():
    limit, files = int(sys.argv[1]), sys.argv[2:]
    try:
        out = run_ctags(files)
    except (OSError, subprocess.CalledProcessError) as e:
        print(f'function_size.py: universal-ctags failed ({e}); tools/setup.sh --tests installs it')
        return 2
    text = {}
    bad = 0
    for row in out.splitlines():
        t = json.loads(row)
        if t.get('_type') != 'tag' or 'end' not in t:
            continue
        path = t['path']
        if path not in text:
            with open(path, encoding='utf-8') as f:
                text[path] = f.read().split('\n')
        n = t['end'] - body_open(text[path], t['line'], t['end'])
        if n > limit:
            print(f"{path}:{t['line']}: {t['name']}: {n} lines (more than {limit})")
            bad = 1
    return bad

sys.exit(main())
