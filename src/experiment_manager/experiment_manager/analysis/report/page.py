"""The report's Markdown as an HTML page, by markdown-it-py (CommonMark with GitHub's tables;
raw HTML in the text is escaped, never passed through), a verdict in bold coloured by what it
says."""

import html

from markdown_it import MarkdownIt

from ..verdicts import FEASIBLE, NOT_FEASIBLE, UNDECIDED

# the HTML class (colour) of a bold verdict
VERDICT_CLASS = {FEASIBLE: 'feasible', NOT_FEASIBLE: 'not-feasible', UNDECIDED: 'undecided'}
STYLE = ('body{font-family:sans-serif;max-width:60em;margin:2em auto}'
         'table{border-collapse:collapse}td,th{border:1px solid #aaa;padding:0.2em 0.5em}'
         '.feasible{color:#1a7f37}.not-feasible{color:#c62828}.undecided{color:#9a6700}')


def _strong_open(renderer, tokens, idx, options, env) -> str:
    """<strong>, with the class of the verdict it holds when it holds one alone."""
    inline = tokens[idx + 1] if idx + 1 < len(tokens) else None
    said = VERDICT_CLASS.get(inline.content) if inline is not None and \
        inline.type == 'text' else None
    return f'<strong class="{said}">' if said else '<strong>'


def _parser() -> MarkdownIt:
    md = MarkdownIt('commonmark', {'html': False}).enable('table')
    md.add_render_rule('strong_open', _strong_open)
    return md


def to_html(text: str, title: str) -> str:
    """The report's Markdown `text` as a whole HTML page titled `title`."""
    return (f'<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>{html.escape(title)}'
            f'</title><style>{STYLE}</style></head><body>\n{_parser().render(text)}'
            '</body></html>\n')
