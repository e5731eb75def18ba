"""A part of the user's own, from a real CAD file (KiCad's TO-220 as STEP, in KiCad's frame):
the worked example of docs/your-part.md reads, is described and drawn by `run --check`
before any run, and runs end to end (on the cores, with small counts)."""

import os

from experiment_manager import experiment_file
from experiment_manager.analysis import part_sheet, report
from experiment_manager.analysis.results import keep_part_file, ResultsWriter
from experiment_manager.commands.run import main as run_main
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import matplotlib.image
import yaml

EXAMPLE = os.path.join(os.path.dirname(__file__), '..', 'config', 'parts', 'to220_kicad.yaml')


def test_the_example_is_described_as_the_run_will_see_it():
    file = experiment_file.load(EXAMPLE)
    lines = part_sheet.describe(file, part_sheet.validator(file))
    text = '\n'.join(lines)
    assert 'TO-220-3_Vertical.step (stated by the file, read in m' in lines[0]
    assert 'size 10.25 x 4.46 x 28.52 mm' in text
    assert 'mass centre at (2.54, 1.11, 8.86) mm in its frame' in text   # not at pin 1
    assert "grasp 'front_up': jaws open 16.00 mm" in text and 'closes on 10.25 mm of part' in text
    assert "grasp 'edge_px'" in text and 'closes on 4.46 mm of part' in text


def test_run_check_draws_the_sheet_without_a_graph(tmp_path, capsys):
    assert run_main(['--check', EXAMPLE, '--output', str(tmp_path)]) == 0
    out = capsys.readouterr().out
    sheet = os.path.join(tmp_path, 'to220_kicad_part.png')
    assert f'sheet: {sheet}' in out
    picture = matplotlib.image.imread(sheet)
    assert picture.shape[0] > 1000 and picture.shape[1] > 600        # 5 rows of 2 panels
    assert (picture[..., :3].std(axis=(0, 1)) > 0.05).all()          # something is drawn


def test_run_check_refuses_a_grasp_that_closes_on_nothing(tmp_path, capsys):
    data = yaml.safe_load(open(EXAMPLE, encoding='utf-8'))
    data['part']['mesh'] = os.path.abspath(os.path.join(os.path.dirname(EXAMPLE),
                                                        data['part']['mesh']))
    for grasp in data['part']['grasps']:        # the mistake: a point beside the body, the
        grasp['grasp_point_mm'] = [7.5, -1.2, 16.0]     # tab's side of it, in front of the tab
    path = tmp_path / 'wrong.yaml'
    path.write_text(yaml.safe_dump(data))
    assert run_main(['--check', str(path), '--output', str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert ("part.grasps[0].grasp_point_mm (grasp 'front_up'): [7.5, -1.2, 16.0] closes on "
            'nothing') in err
    assert not os.path.exists(tmp_path / 'to220_kicad_part.png')


def test_the_example_runs_end_to_end(tmp_path):
    data = yaml.safe_load(open(EXAMPLE, encoding='utf-8'))
    data['experiments'] = [
        {'id': 'sweep', 'type': 'table_sweep', 'iterations': 1,
         'counts': {'first': 10, 'last': 30, 'step': 10}},
        {'id': 'feeder', 'type': 'feeder_emptying', 'iterations': 1, 'parts': 30,
         'optimal_range': [10, 20], 'max_vibrations': 60}]
    file = experiment_file.parse(yaml.safe_dump(data), EXAMPLE)
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), file.text, False) as writer:
        keep_part_file(file.part.mesh_path, file.path, str(tmp_path))
        summary = Runner(file, [backend], writer).run()
    # the run directory reads on its own (run --resume, the pictures): the STEP file is kept
    # where its experiment.yaml names it
    again = experiment_file.load(str(tmp_path / 'experiment.yaml'))
    assert again.part.mesh_path == str(tmp_path / 'TO-220-3_Vertical.step')
    sweep = summary.experiments['sweep']
    assert sweep.n_star is not None
    feeder = summary.experiments['feeder']
    assert feeder.iterations == 1 and feeder.emptied in (0, 1)
    # the report names the part file, its frame, its pieces and its grasps, with its sheet
    part_sheet.write_account(file, str(tmp_path))
    report.write(str(tmp_path))
    text = open(tmp_path / 'report.md', encoding='utf-8').read()
    assert '## The part' in text and 'TO-220-3_Vertical.step' in text
    assert 'mass centre at (2.54, 1.11, 8.86) mm in its frame' in text
    assert ('9 convex piece(s) of 11, 22, 17, 16, 17, 14, 14, 14, 25 vertices, 496.8 mm^3 '
            'together, +2.0 %') in text and 'cut into convex pieces by CoACD' in text
    # in centimetres every piece takes pybullet's margin off whole (in metres its thinnest
    # stayed swollen by up to 0.76 mm, which the report said)
    assert ("each piece inset by pybullet's 0.01 mm margin, so that it collides this surface "
            '(its edges rounded by the margin)') in text and 'swollen' not in text
    assert '](part.png)' in text and os.path.getsize(tmp_path / 'part.png') > 10_000
    assert '## Why parts were turned down' in text and 'stops most' in text


def test_an_open_mesh_export_in_mm_with_its_origin_away_is_checked_on_its_hull(tmp_path):
    """A new user's export: the TO-220 in mm, its origin 47 mm from the part, a few triangles
    missing. The grasp at the body's centre is accepted (its closing line crosses the hull on
    both sides, where the open mesh has one side missing), one beside the part refused."""
    import numpy as np
    import trimesh
    mesh = trimesh.load(os.path.join(os.path.dirname(EXAMPLE), 'TO-220-3_Vertical.step'),
                        force='mesh')
    mesh.apply_scale(1000.0)
    mesh.apply_translation([40.0, -25.0, 3.0])
    mesh.update_faces(np.arange(len(mesh.faces))[5:])
    assert not mesh.is_watertight
    mesh.export(tmp_path / 'to220.obj')
    text = """id: newuser
part:
  model: mesh
  mesh: to220.obj
  units: mm
  mass_g: 2
  place: {axis: [0, 0, -1], seat_offset_mm: -3}
  grasps:
    - {name: across, up_axis: [0, -1, 0], closing_axis: [1, 0, 0], jaw_opening_mm: 16,
       grasp_point_mm: POINT}
experiments:
  - {id: sweep, type: table_sweep, iterations: 1, counts: {first: 20, last: 40, step: 20}}
"""
    path = tmp_path / 'part.yaml'
    path.write_text(text.replace('POINT', '[42.54, -24.06, 11.5]'))
    loaded = experiment_file.load(str(path))
    lines = part_sheet.describe(loaded, part_sheet.validator(loaded))
    assert any("grasp 'across'" in line and 'closes on 10.25 mm of part' in line
               for line in lines), lines
    path.write_text(text.replace('POINT', '[0, 0, 0]'))
    assert run_main(['--check', str(path), '--output', str(tmp_path)]) == 2


def test_grasps_auto_takes_the_proposals_and_check_prints_them_to_paste(tmp_path, capsys):
    with open(EXAMPLE, encoding='utf-8') as f:
        data = yaml.safe_load(f)
    data['part']['mesh'] = os.path.join(os.path.dirname(os.path.abspath(EXAMPLE)),
                                        data['part']['mesh'])
    data['part']['grasps'] = 'auto'
    path = tmp_path / 'auto.yaml'
    path.write_text(yaml.safe_dump(data))
    file = experiment_file.load(str(path))
    assert file.auto_grasps and 'up+y_close+x' in [g.name for g in file.grasps]
    assert run_main(['--check', str(path), '--output', str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    pasted = printed[printed.index('    grasps:\n'):printed.index('sheet:')]
    # what it prints, pasted in place of `auto`, reads back as the same grasps
    data['part']['grasps'] = yaml.safe_load(pasted)['grasps']
    path.write_text(yaml.safe_dump(data))
    again = experiment_file.load(str(path))
    assert not again.auto_grasps
    assert [g.name for g in again.grasps] == [g.name for g in file.grasps]
    for a, b in zip(again.grasps, file.grasps, strict=True):
        assert abs(a.jaw_opening - b.jaw_opening) < 1e-5
        assert max(abs(x - y) for x, y in zip(a.grasp_point, b.grasp_point, strict=True)) < 1e-5
    # a mesh part with no grasps is told of auto
    del data['part']['grasps']
    path.write_text(yaml.safe_dump(data))
    assert run_main(['--check', str(path), '--output', str(tmp_path)]) == 2
    assert "or 'auto' for those proposed from its geometry" in capsys.readouterr().err
