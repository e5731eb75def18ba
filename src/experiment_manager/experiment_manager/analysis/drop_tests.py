"""A drop test's figures: the aspects its parts came to rest on, against the quasi-static
prediction and a real drop test's counts (pick_common.parts.aspects). Pure: no rclpy, no
simulator."""

from collections import Counter

from pick_common.parts import aspects
from pick_common.stats import wilson_interval

from ..experiment_file import DropTestExperiment, Ran
from .summary import AspectCount, DropTest, Measured


def summary(file: Ran, exp: DropTestExperiment,
            rows: list[dict], base: dict) -> DropTest:
    """A drop test's aspects: each one's count, share and 95 % interval of the drops at rest
    on an aspect, the quasi-static share, and against the measured counts (when the file
    gives them) each one's difference and the G-test's p (aspects.agreement; agrees: p at
    least 0.05). `base`: the fields every summary has (metrics' _base)."""
    counts = Counter(r['aspect'] for r in rows if r['aspect'])
    other = counts.pop(aspects.OTHER, 0)
    drops = sum(counts.values())
    measured = dict(exp.measured)
    measured_drops = sum(measured.values())
    found = []
    for a in file.aspects:
        k = counts.get(a.name, 0)
        m = measured.get(a.name) if measured else None
        share = k / drops if drops else None
        m_share = m / measured_drops if m is not None and measured_drops else None
        found.append(AspectCount(
            name=a.name, normal=[round(v, 6) for v in a.normal], count=k, share=share,
            ci95=list(wilson_interval(k, drops)), quasi_static=a.quasi_static, measured=m,
            measured_share=m_share,
            difference=share - m_share if None not in (share, m_share) else None))
    agreement = None
    if measured_drops:
        p = aspects.agreement(dict(counts), measured)
        agreement = Measured(drops=measured_drops, p=p, agrees=p >= 0.05)
    return DropTest(**base, drops=drops, height_mm=round(exp.bin.drop_height * 1000, 6),
                    aspects=found, other=other, measured=agreement)
