"""For the paper's test-case files (ids pth0, pth1, pth2): its three findings and its figures
beside this run's, and where and why ours differ (verdicts.against_paper)."""

from ..verdicts import against_paper
from .base import Run, Section


class AgainstPaper(Section):
    def lines(self, run: Run) -> list[str]:
        return against_paper(run.summary, run.paper) if run.paper else []
