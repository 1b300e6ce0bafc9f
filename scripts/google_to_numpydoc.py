"""Convert Google-style docstring sections (``Args:``, ``Raises:``, ``Attributes:`` ...) to
numpydoc (``Parameters`` / ``----------``) in the given files, in place; prints what it changed.

    python scripts/google_to_numpydoc.py src/mindgrasp_bag/mindgrasp_bag/reader.py ...

tests/docs/test_docstring_style.py keeps one style (numpydoc) in src/.
"""
import re
import sys

HEAD = re.compile(r'^(\s*)(Args|Arguments|Attributes|Raises|Returns|Yields|Examples?|Notes?):\s*$')
NAMES = {'Args': 'Parameters', 'Arguments': 'Parameters', 'Attributes': 'Attributes',
         'Raises': 'Raises', 'Returns': 'Returns', 'Yields': 'Yields', 'Example': 'Examples',
         'Examples': 'Examples', 'Note': 'Notes', 'Notes': 'Notes'}
ENTRY = re.compile(r'^(\s*)([\w.*]+(?:,\s*[\w.*]+)*)(?:\s*\(([^)]*)\))?:\s?(.*)$')


def indent_of(line):
    return len(line) - len(line.lstrip())


def convert(text):
    lines = text.split('\n')
    out = []
    i = 0
    while i < len(lines):
        m = HEAD.match(lines[i])
        if not m:
            out.append(lines[i])
            i += 1
            continue
        ind, kind = m.group(1), NAMES[m.group(2)]
        base = len(ind)
        out += [f'{ind}{kind}', f'{ind}{"-" * len(kind)}']
        i += 1
        body = []
        while i < len(lines):
            line = lines[i]
            if line.strip() and indent_of(line) <= base:
                break
            if not line.strip():
                # blank: the section ends unless the next non-blank line is deeper
                j = i
                while j < len(lines) and not lines[j].strip():
                    j += 1
                if j >= len(lines) or indent_of(lines[j]) <= base:
                    break
            body.append(line)
            i += 1
        if kind in ('Parameters', 'Attributes', 'Raises'):
            for line in body:
                if not line.strip():
                    out.append('')
                    continue
                if indent_of(line) == base + 4:
                    e = ENTRY.match(line)
                    if e is None:
                        raise ValueError(f'not an entry: {line!r}')
                    name, typ, desc = e.group(2), e.group(3), e.group(4)
                    out.append(f'{ind}{name}' + (f' : {typ}' if typ else ''))
                    if desc:
                        out.append(f'{ind}    {desc[0].upper()}{desc[1:]}')
                else:   # continuation, one level less deep
                    out.append(line[4:] if line.startswith(' ' * (base + 8)) else line)
        else:
            for line in body:
                out.append(line)
    return '\n'.join(out)


if __name__ == '__main__':
    from pathlib import Path

    for name in sys.argv[1:]:
        path = Path(name)
        src = path.read_text(encoding='utf-8')
        new = convert(src)
        if new != src:
            path.write_text(new, encoding='utf-8')
            print('converted', path)
