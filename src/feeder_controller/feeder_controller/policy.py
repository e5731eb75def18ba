"""The optimal-range policy of the feeder and vibrating table (paper section 4.3.2).

After each validity check of the table: if a part is valid, pick it; if none is and the count is
within [min*, max*], vibrate; if the count is below min*, feed up to max* (or until the feeder is
empty), then vibrate; stop when the feeder and the table are empty, or at the vibration limit.
With a dose (max_feed; the paper has none), a feed brings at most max_feed parts, and the feeds
go on, a vibration after each, until the count reaches max* (a part found valid is picked
first), as a hopper that doses a refill over time.

Deciding and applying are separate: `decide` changes nothing but the table count it is told
(and whether a dosed fill goes on); `fed` and `vibrated` record what the world actually did,
so a failed world command leaves the state true.
"""

from dataclasses import dataclass

from pick_common.errors import check_int, InvalidArgument, Limit

PICK, VIBRATE, FEED_AND_VIBRATE, STOP_EMPTY, STOP_VIBRATION_LIMIT = range(5)
NAMES = ('pick', 'vibrate', 'feed and vibrate', 'stop: empty', 'stop: vibration limit')
MAX_FEEDER_PARTS = 100_000
MAX_TABLE_PARTS = 5000
MAX_VIBRATIONS = 1_000_000
# The range of each setting, by the feeder_controller node's parameter name.
LIMITS = {
    'feeder.parts': Limit(1, MAX_FEEDER_PARTS, integer=True),
    'feeder.max_count': Limit(1, MAX_TABLE_PARTS, integer=True),
    'feeder.min_count': Limit(1, MAX_TABLE_PARTS, integer=True),    # and at most max_count
    'feeder.max_vibrations': Limit(1, MAX_VIBRATIONS, integer=True),
    'feeder.max_feed': Limit(0, MAX_TABLE_PARTS, integer=True),      # 0: no limit
}


@dataclass(frozen=True)
class FeederConfig:
    """feeder_parts: parts loaded into the feeder at the start of a run. min_count, max_count:
    the optimal range [min*, max*] of parts on the table. max_vibrations: the limit. max_feed:
    the most parts one feed brings (a hopper that doses a refill over several vibrations); 0,
    the paper's: the whole shortfall at once."""

    feeder_parts: int = 100
    min_count: int = 20
    max_count: int = 30
    max_vibrations: int = 200
    max_feed: int = 0


def check_feeder(cfg: FeederConfig) -> FeederConfig:
    """Check every field; raise InvalidArgument naming the first that is wrong."""
    LIMITS['feeder.parts'].check('feeder_parts', cfg.feeder_parts)
    high = LIMITS['feeder.max_count'].check('max_count', cfg.max_count)
    check_int('min_count', cfg.min_count, low=1, high=high)
    LIMITS['feeder.max_vibrations'].check('max_vibrations', cfg.max_vibrations)
    LIMITS['feeder.max_feed'].check('max_feed', cfg.max_feed)
    return cfg


@dataclass
class FeederState:
    """Counts of a run. picked is derived: what left the feeder and is no longer on the table."""

    loaded: int
    in_feeder: int
    on_table: int = 0
    vibrations: int = 0
    feeds: int = 0
    last: int = -1          # the last decision, -1 before the first
    filling: bool = False   # below min* once, and not yet fed up to max*

    @property
    def picked(self) -> int:
        return self.loaded - self.in_feeder - self.on_table


@dataclass(frozen=True)
class Step:
    """A decision and how many parts to feed before vibrating (0 unless FEED_AND_VIBRATE)."""

    decision: int
    feed: int = 0

    @property
    def vibrates(self) -> bool:
        return self.decision in (VIBRATE, FEED_AND_VIBRATE)


class FeederPolicy:
    """One run of the feeder: starts loaded with `feeder_parts`, the table empty."""

    def __init__(self, config: FeederConfig) -> None:
        self.config = check_feeder(config)
        self.state = FeederState(loaded=config.feeder_parts, in_feeder=config.feeder_parts)

    def decide(self, valid_parts: int, parts_on_table: int) -> Step:
        """The next step, given the last check's valid parts and the parts on the table now.

        Parts leave the table only by picks, so the count cannot exceed the last one.
        """
        s, cfg = self.state, self.config
        on_table = check_int('parts_on_table', parts_on_table, low=0, high=s.on_table)
        valid = check_int('valid_parts', valid_parts, low=0, high=on_table)
        s.on_table = on_table
        if s.in_feeder == 0 and on_table == 0:
            step = Step(STOP_EMPTY)
        elif valid > 0:
            step = Step(PICK)
        elif s.vibrations >= cfg.max_vibrations:
            step = Step(STOP_VIBRATION_LIMIT)
        elif (on_table < cfg.min_count or s.filling) and s.in_feeder > 0 \
                and on_table < cfg.max_count:
            short = min(cfg.max_count - on_table, s.in_feeder)
            feed = min(short, cfg.max_feed) if cfg.max_feed else short
            s.filling = feed < short
            step = Step(FEED_AND_VIBRATE, feed)
        else:
            s.filling = False
            step = Step(VIBRATE)
        s.last = step.decision
        return step

    def fed(self, count: int) -> None:
        """Record that `count` parts went from the feeder onto the table."""
        if not 0 < count <= self.state.in_feeder:
            raise InvalidArgument('fed', count, f'must be within [1, {self.state.in_feeder}]')
        self.state.in_feeder -= count
        self.state.on_table += count
        self.state.feeds += 1

    def vibrated(self) -> None:
        """Record one vibration of the table."""
        self.state.vibrations += 1
