"""Studies: scripts that answer a question about finished runs and print the evidence a page of
docs/ cites (how often a decision on few runs is wrong, what today's rules would have taken on
a recorded run, what a change to the cell did to the same drops, where parts were turned
down). Apart from bench/, which holds timings: a study's figures are about answers, not speed.
Each runs from the top of the workspace on run directories:

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
