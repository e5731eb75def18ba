"""The documentation and the code keep the shape they promise: every relative link in the
Markdown pages and its anchor resolve; no tracker number in src/ or docs/ and no date in a
comment of src/'s code (what holds today lives there, how it came to be in CHANGELOG.md); the
README stays a newcomer's page of at most 120 lines, and no module of src/ passes 400 lines
(past that it usually holds two jobs)."""

import glob
import os
import re

import pytest

TOP = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
PAGES = sorted([os.path.join(TOP, 'README.md'), os.path.join(TOP, 'CHANGELOG.md')]
               + glob.glob(os.path.join(TOP, 'docs', '*.md'))
               + glob.glob(os.path.join(TOP, 'src', '*', 'README.md')))
LINK = re.compile(r'\[[^\]]*\]\(([^)\s]+)\)')
TRACKER = re.compile(r'\b[Ii]ssues?\s+\d+|\b[Ii]ssue\s*\n\s*\d+')
DATE = re.compile(r'#.*\b20\d\d-\d\d-\d\d\b')
# when a figure was measured, rather than what holds: a date, a day without its year, a commit
# or a session named as where a figure came from
WHEN = re.compile(r'\b20\d\d-\d\d-\d\d\b|\b(?:until|since|before|after|on|of) 1[0-2]-[0-3]\d\b'
                  r'|\b(?:as of|at|on) commit\b|\bat [0-9a-f]{7,40}\b|\([0-9a-f]{7}\)'
                  r'|\b(?:this|that|today\'s) session\b|\b(?:first|second|third|fourth) session\b'
                  r'|\bthis (?:morning|evening)\b')
# the pages that say what holds; dated measurements live on studies.md and benchmarks.md, the
# history in CHANGELOG.md
REFERENCE = [p for p in PAGES if os.path.basename(p) not in ('studies.md', 'benchmarks.md',
                                                             'CHANGELOG.md')]


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but '-' and '_' dropped, spaces
    to '-'."""
    text = re.sub(r'[`*]', '', heading.strip().lower())
    return re.sub(r'[^\w\- ]', '', text).replace(' ', '-')


def _anchors(path: str) -> set[str]:
    with open(path, encoding='utf-8') as f:
        text = re.sub(r'```.*?```', '', f.read(), flags=re.S)
    return {_slug(m.group(1)) for m in re.finditer(r'^#+ (.+)$', text, re.M)}


def _links(path: str) -> list[str]:
    with open(path, encoding='utf-8') as f:
        text = re.sub(r'```.*?```', '', f.read(), flags=re.S)
    return [t for t in LINK.findall(text) if not re.match(r'[a-z]+:', t)]


@pytest.mark.parametrize('page', PAGES, ids=lambda p: os.path.relpath(p, TOP))
def test_every_relative_link_and_anchor_resolves(page):
    broken = []
    for target in _links(page):
        path, _, anchor = target.partition('#')
        resolved = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
        if not os.path.exists(resolved):
            broken.append(target)
        elif anchor and resolved.endswith('.md') and anchor not in _anchors(resolved):
            broken.append(target)
    assert not broken, f'{os.path.relpath(page, TOP)}: {broken}'


def _files(*patterns: str) -> list[str]:
    return sorted(p for pattern in patterns
                  for p in glob.glob(os.path.join(TOP, pattern), recursive=True))


def test_no_tracker_number_in_src_or_docs():
    found = []
    for path in _files('src/**/*.py', 'src/**/*.md', 'src/**/*.yaml', 'docs/*.md'):
        with open(path, encoding='utf-8') as f:
            found += [f'{os.path.relpath(path, TOP)}: {m.group(0)!r}'
                      for m in TRACKER.finditer(f.read())]
    assert not found, found


def test_no_date_in_a_comment_of_the_code():
    found = []
    for path in _files('src/**/*.py'):
        with open(path, encoding='utf-8') as f:
            found += [f'{os.path.relpath(path, TOP)}:{n}' for n, line in enumerate(f, 1)
                      if DATE.search(line)]
    assert not found, found


def test_no_date_or_when_it_was_measured_in_the_code_or_on_a_reference_page():
    found = []
    for path in _files('src/**/*.py', 'studies/*.py') + REFERENCE:
        with open(path, encoding='utf-8') as f:
            found += [f'{os.path.relpath(path, TOP)}:{n}: {m.group(0)!r}'
                      for n, line in enumerate(f, 1) for m in WHEN.finditer(line)]
    assert not found, found


def test_the_readme_is_at_most_120_lines():
    with open(os.path.join(TOP, 'README.md'), encoding='utf-8') as f:
        assert len(f.read().splitlines()) <= 120


def test_no_module_of_src_passes_400_lines():
    long = {}
    for path in _files('src/*/*/**/*.py'):
        if '/test/' in path:
            continue
        with open(path, encoding='utf-8') as f:
            count = len(f.read().splitlines())
        if count > 400:
            long[os.path.relpath(path, TOP)] = count
    assert not long, long


def test_the_checks_above_can_fail():
    assert TRACKER.search('as issue 43 asked') and TRACKER.search('the issue\n  43')
    assert DATE.search('x = 1  # measured 2026-11-27') and not DATE.search('x = "2026-11-27"')
    for said in ('measured 2026-11-27', 'the default until 11-25', 'as of commit 10416e4',
                 'at a147eca, 59 min', 'the metres world (a4933a7)', "this session's run",
                 'the fourth session', 'this morning'):
        assert WHEN.search(said), said
    assert not WHEN.search('a 5 mm part at 30 Hz, 10-20 % of the time, seed 11')
    assert _slug('## Results (the run directory)'[3:]) == 'results-the-run-directory'
