"""The command line: `run` (start a graph, send the experiment, print the verdicts), `replay`
(play a recording back on the graph), and what `run` needs: the processes of a graph
(`launcher`, `supervisor`), a claim on a namespace (`claim`) and a clean Ctrl-C
(`interrupt`)."""
