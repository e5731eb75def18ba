"""Studies: scripts that answer a question and print the evidence a page of docs/ cites. Apart
from bench/, which holds timings: a study's figures are about answers, not speed, and no study
imports from bench/ (what both use, the test case's files and a run of one on the cores, is
`cases`). Each runs from the top of the workspace.

Of the physics (docs/physics.md), each with `--small`, the size its smoke test runs it at:

    tools/ws python -m studies.answers        # the test case's answers at finer steps
    tools/ws python -m studies.convergence    # the physics' own figures against finer settings
    tools/ws python -m studies.creep          # what a pile does after it is called at rest
    tools/ws python -m studies.feeds          # where fed parts land, and what tunnels
    tools/ws python -m studies.lean           # where a coarse step changes a bin's answer
    tools/ws python -m studies.moves          # where each feeder move carries parts
    tools/ws python -m studies.spills         # spills of feeder runs by solver setting
    tools/ws python -m studies.standing       # how parts stand after moves
    tools/ws python -m studies.throws         # parts thrown by the solver
    tools/ws python -m studies.vibration      # which vibration serves a feeder
    tools/ws python -m studies.gripper_stages # which stage a gripper's size moves
    tools/ws python -m studies.roll           # which stage a lone part's roll ends at
    tools/ws python -m studies.part_files     # one part from its STEP, STL or a moved frame

Of finished runs (how often a decision on few runs is wrong, what today's rules would have
taken on a recorded run, what a change to the cell did to the same drops, where parts were
turned down), on run directories:

    tools/ws python -m studies.feeder_decisions table RUN_DIR...   # decisions on few runs
    tools/ws python -m studies.replay_decisions RUN_DIR...         # today's rules, replayed
    tools/ws python -m studies.replay_race RUN_DIR...              # the bins' race, replayed
    tools/ws python -m studies.sweep_sampling RUN_DIR              # a sweep's looks, replayed
    tools/ws python -m studies.compare_runs RUN_A RUN_B            # two runs, the same seeds
    tools/ws python -m studies.run_stages RUN_DIR                  # where parts were stopped

tests/test_studies.py runs each on a small recorded run, so a study a page cites is one that
still runs. Re-deciding a finished run with today's rules is the `decide` command, not a
study.
"""
