"""The board's answer as data, `<output>/<board id>_board.json`: a model per record, its JSON
Schema published as docs/board.schema.json:

    python -m experiment_manager.experiment_file.board.board_json --schema docs/board.schema.json

writes it from this module (a test checks that the committed file is current). No rclpy."""

from typing import Literal

from pydantic import BaseModel, ConfigDict

from ..schema import json_schema_text, schema_command

BOARD_JSON_VERSION = 1
# decided: its options ran; refused: it cannot be decided (its reason); not through-hole: an
# SMD part or a footprint of neither kind; not run: a part to decide whose run has not ended.
STATUSES = ('decided', 'refused', 'not through-hole', 'not run')


class _Record(BaseModel):
    model_config = ConfigDict(extra='forbid', frozen=True)


class BoardOption(_Record):
    """One option of a part as its run decided it: the option (its kind: 'static bin',
    'vibrating table, gripper cup', ...), its verdict and the first of its reasons."""
    option: str
    verdict: str
    reason: str


class BoardPartRecord(_Record):
    """One distinct part of the board (a 3D model at one offset, scale and rotation)."""
    name: str
    model: str                      # the STEP file read, or the model path as the board has it
    references: list[str]
    quantity: int                   # per board
    status: Literal[STATUSES]
    reason: str                     # why it is not decided; '' when it is
    mass: str                       # the mass's account (from the model's solids, or given)
    left_out: dict[str, str]        # grippers and experiments that cannot run for it, and why
    run: str                        # its run directory; '' before it ran
    file_sha256: str                # of the experiment file it ran: a run again keeps it if equal
    options: list[BoardOption]
    best: str | None                # the first feasible option in the cell's order


class BoardRecord(_Record):
    model_config = ConfigDict(title=f'pick_sim board answer, version {BOARD_JSON_VERSION}')
    board_json_version: Literal[BOARD_JSON_VERSION]
    board: str                      # the .kicad_pcb file
    id: str
    boards_per_hour: float
    parts: list[BoardPartRecord]


def schema_text() -> str:
    """The JSON Schema of <id>_board.json, as docs/board.schema.json holds it."""
    return json_schema_text(BoardRecord)


def main(argv: list[str] | None = None) -> int:
    return schema_command(BoardRecord, 'the board answer', __doc__.split('\n\n')[0], argv)


if __name__ == '__main__':
    raise SystemExit(main())
