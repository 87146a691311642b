#!/usr/bin/env python3
"""function_size.py MAX FILE... - functions (lambdas included) whose body spans more than MAX
lines, as clang-tidy's readability-function-size LineThreshold counts them: the line of the
closing brace minus the line of the opening one. Function extents come from universal-ctags."""
import json, subprocess, sys

def body_open(lines, start, end):
    # The body's opening brace: the one matching the last '}' of the definition's end line,
    # found backwards. (Forwards, the first '{' outside the parameters could be a member's
    # brace initializer in a constructor's list, before the body.) The project's sources hold
    # no brace in a string or character literal (checked when this was written).
    depth = 0
    for i in range(end - 1, start - 2, -1):
        line = lines[i]
        if i == end - 1:
            line = line[:line.rfind('}') + 1]
        for ch in reversed(line):
            if ch == '}':
                depth += 1
            elif ch == '{':
                depth -= 1
                if depth == 0:
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
