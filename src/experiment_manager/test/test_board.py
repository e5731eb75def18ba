"""A KiCad board as the input: KiCad's ecc83 demo board and the 3D models it names
(config/boards/), read into its distinct parts, each part's experiment file, its mass from the
model's solids and its grasps; and bad boards, each refused naming the file, the line or key,
and what is wrong."""

import os
import shutil

from experiment_manager import experiment_file
from experiment_manager.experiment_file.board import (
    answer,
    cut_side_by_side,
    expand,
    kicad,
    load_board,
    placement,
    settle,
    table,
    write_parts,
)
from experiment_manager.experiment_file.board.parts import (
    board_parts,
    DECIDE,
    NOT_THROUGH_HOLE,
    REFUSED,
)
from experiment_manager.experiment_file.loading import part_of
from experiment_manager.experiment_file.part import geometry
import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts import pieces
from pick_common.parts.solids import body_density, LEADS, solid_mass
import pytest
import yaml

BOARDS = os.path.join(os.path.dirname(__file__), '..', 'config', 'boards')
PCB = os.path.join(BOARDS, 'ecc83-pp.kicad_pcb')
MODELS = os.path.join(BOARDS, '3dmodels')
RESISTOR = 'R_Axial_DIN0207_L6.3mm_D2.5mm_P7.62mm_Horizontal'
DOCS = os.path.join(os.path.dirname(__file__), '..', '..', '..', 'docs')


def _board_file(tmp_path, pcb=PCB, models=MODELS, **board) -> str:
    data = yaml.safe_load(open(os.path.join(BOARDS, 'ecc83.yaml')))
    data['board'] = {'pcb': os.path.abspath(pcb), 'models': os.path.abspath(models),
                     'boards_per_hour': 30, **board}
    path = tmp_path / 'board.yaml'
    path.write_text(yaml.safe_dump(data))
    return str(path)


def test_the_demo_board_reads_into_its_distinct_parts_with_their_references():
    board = load_board(os.path.join(BOARDS, 'ecc83.yaml'))
    parts = {p.name: p for p in board.parts}
    assert parts[RESISTOR].references == ('R1', 'R2', 'R3', 'R4')
    assert parts[RESISTOR].status == DECIDE
    assert parts['Altech_AK300_1x02_P5.00mm_45-Degree'].quantity == 4
    assert parts['CP_Radial_D10.0mm_P5.00mm'].references == ('C1',)
    # the valve's model is the project's own and is not here: refused, with the line
    assert parts['ecc83'].status == REFUSED
    assert 'ecc83.wrl does not exist' in parts['ecc83'].reason
    assert 'board line' in parts['ecc83'].reason
    # mounting holes are neither through-hole nor SMD in KiCad 6: not decided
    assert parts['MountingHole_3'].status == NOT_THROUGH_HOLE
    assert sum(p.quantity for p in board.parts) == 15     # every footprint, in one row or other
    lines = table(board)
    assert len(lines) == 2 + len(board.parts)
    assert any('R1 R2 R3 R4' in line for line in lines)


def test_each_part_becomes_an_experiment_file_with_its_requirement_mass_and_grasps(tmp_path):
    board = expand(yaml.safe_load(open(_board_file(tmp_path))), str(tmp_path / 'board.yaml'))
    data = yaml.safe_load(board.files[RESISTOR])
    assert data['requirements']['parts_per_hour'] == 30 * 4     # boards per hour x quantity
    assert data['part']['place'] == {'axis': [0.0, 0.0, -1.0], 'seat_offset_mm': 0.0}
    assert data['part']['grasps'] == 'auto'
    mass = solid_mass(data['part']['mesh'])
    assert data['part']['mass_g'] == pytest.approx(mass.mass * 1000, abs=1e-4)
    file = experiment_file.parse(board.files[RESISTOR], str(tmp_path / 'r.yaml'))
    # the resistor's body is round about x above its mass centre, which its bent leads pull
    # below the body's axis: the jaws close across the body on its axis, at any roll
    (grasp,) = file.setup.grasps
    centre = geometry(file.setup.part).mass_centre
    assert grasp.closing_axis == (0.0, 1.0, 0.0)
    point = np.array(grasp.grasp_point) * 1000
    assert point[2] == pytest.approx(1.25, abs=0.05)           # the body's axis, z 1.25 mm
    assert centre[2] * 1000 < point[2] - 0.1


def test_a_given_mass_and_grasps_replace_the_models(tmp_path):
    path = _board_file(tmp_path, parts={RESISTOR: {'mass_g': 0.25}})
    board = load_board(path)
    assert yaml.safe_load(board.files[RESISTOR])['part']['mass_g'] == 0.25
    assert 'given in board.parts' in board.masses[RESISTOR]
    with pytest.raises(InvalidArgument) as err:
        load_board(_board_file(tmp_path, parts={'R_none': {'mass_g': 0.25}}))
    assert err.value.field == 'board.parts.R_none' and RESISTOR in err.value.rule


def test_the_mass_is_the_leads_and_the_body_by_their_colours_and_densities():
    step = os.path.join(MODELS, 'Resistor_THT.3dshapes', f'{RESISTOR}.step')
    mass = solid_mass(step)
    assert mass.lead_volume > 0 and mass.body_volume > mass.lead_volume
    assert mass.body == body_density(step) and mass.body.family == 'axial resistor'
    assert mass.mass == pytest.approx(mass.lead_mass + mass.body_mass)
    assert mass.lead_mass == pytest.approx(mass.lead_volume * LEADS[1] * 1000)
    assert 'assumed' in mass.account() and 'CRC' in mass.account()


def test_kicad_5_modules_8_properties_hidden_models_and_inch_offsets_are_read(tmp_path):
    pcb = tmp_path / 'old.kicad_pcb'
    pcb.write_text("""(kicad_pcb (version 20171130) (host pcbnew 5.1)
  (module Resistor_THT:R_Axial (layer F.Cu) (at 10 20)
    (fp_text reference R7 (at 0 0) (layer F.SilkS))
    (pad 1 thru_hole circle (at 0 0) (size 1.6 1.6) (drill 0.8) (layers *.Cu))
    (model ${KISYS3DMOD}/Resistor_THT.3dshapes/R_Axial.wrl
      (at (xyz 0 0 0.1)) (scale (xyz 1 1 1)) (rotate (xyz 0 0 90))))
  (module Pad:SMD (layer B.Cu) (attr smd)
    (fp_text reference C3 (at 0 0) (layer F.SilkS)))
  (module Logo:POLY (layer F.Cu)
    (fp_text reference G1 (at 0 0) (layer F.SilkS))
    (pad 1 smd rect (at 0 0) (size 1 1) (layers F.Cu)))
  (footprint "X:Y" (layer "F.Cu") (attr through_hole)
    (property "Reference" "U5")
    (model "a.wrl" hide (offset (xyz 0 0 0)))
    (model "b.step" (hide yes) (offset (xyz 0 0 0)))))
""")
    _, fps = kicad.read(str(pcb))
    r7, c3, g1, u5 = fps
    assert (r7.reference, r7.kind, r7.side) == ('R7', 'through_hole', 'top')
    assert g1.kind == 'other'           # KiCad 5, no type and no plated hole: not inserted
    assert r7.models[0].offset == pytest.approx((0.0, 0.0, 2.54))       # 0.1 inch
    assert (c3.kind, c3.side) == ('smd', 'bottom')
    assert (u5.reference, u5.models, len(u5.hidden)) == ('U5', (), 2)
    axis, seat = placement(r7.models[0])
    assert axis == [0.0, 0.0, -1.0] and seat == pytest.approx(2.54)    # a turn about z keeps z


def test_a_model_turned_in_the_board_places_along_the_turned_axis():
    axis, seat = placement(kicad.Model('m.step', offset=(0, 0, 1.5), rotate=(90, 0, 0)))
    # KiCad draws it turned -90 degrees about x, which takes the file's +y to -z: the leads
    # go into the board along the file's +y
    assert axis == pytest.approx([0.0, 1.0, 0.0]) and seat == pytest.approx(1.5)


def test_a_truncated_board_is_refused_with_the_line_left_open(tmp_path):
    text = open(PCB).read()
    cut = tmp_path / 'cut.kicad_pcb'
    cut.write_text(text[:len(text) // 2])
    with pytest.raises(InvalidArgument) as err:
        kicad.read(str(cut))
    assert err.value.field == 'board.pcb' and err.value.value == str(cut)
    assert 'is not closed by the end of the file' in err.value.rule
    assert 'truncated' in err.value.rule and err.value.rule.startswith('line ')


def test_a_board_with_no_through_hole_part_is_refused(tmp_path):
    smd = tmp_path / 'smd.kicad_pcb'
    smd.write_text(open(PCB).read().replace('(attr through_hole)', '(attr smd)'))
    with pytest.raises(InvalidArgument) as err:
        load_board(_board_file(tmp_path, pcb=smd))
    assert err.value.field == 'board.pcb' and 'has no through-hole footprint' in err.value.rule


def test_a_model_that_does_not_exist_and_a_wrl_with_no_step_are_refused_and_the_rest_goes_on(
        tmp_path):
    models = tmp_path / 'models'
    shutil.copytree(MODELS, models)
    os.remove(models / 'Resistor_THT.3dshapes' / f'{RESISTOR}.step')
    (models / 'Resistor_THT.3dshapes' / f'{RESISTOR}.wrl').write_text('#VRML V2.0 utf8\n')
    os.remove(models / 'Capacitor_THT.3dshapes' / 'CP_Radial_D10.0mm_P5.00mm.step')
    board = load_board(_board_file(tmp_path, models=models))
    parts = {p.name: p for p in board.parts}
    assert parts[RESISTOR].status == REFUSED
    assert 'has no STEP file beside it' in parts[RESISTOR].reason
    assert parts['CP_Radial_D10.0mm_P5.00mm'].status == REFUSED
    assert 'does not exist' in parts['CP_Radial_D10.0mm_P5.00mm'].reason
    assert parts['Altech_AK300_1x02_P5.00mm_45-Degree'].status == DECIDE
    assert set(board.files) == {'Altech_AK300_1x02_P5.00mm_45-Degree',
                                'C_Disc_D4.7mm_W2.5mm_P5.00mm'}


def test_a_relative_model_path_is_looked_for_beside_the_board_then_in_the_library(tmp_path):
    # KiCad's resolver (common/filename_resolver.cpp, ResolvePath): the project's folder first,
    # then the partial path under the 3D library's folder
    board_dir, library = tmp_path / 'board', tmp_path / 'library'
    for folder in (board_dir / 'Mine.3dshapes', library / 'Mine.3dshapes'):
        folder.mkdir(parents=True)
    (library / 'Mine.3dshapes' / 'a.step').write_text('ISO-10303-21;')
    path, why = kicad.resolve('Mine.3dshapes/a.wrl', str(board_dir), str(library), {})
    assert (path, why) == (str(library / 'Mine.3dshapes' / 'a.wrl'), '')
    # the library from the environment when board.models is not given
    path, _ = kicad.resolve('Mine.3dshapes/a.wrl', str(board_dir), None,
                            {'KICAD8_3DMODEL_DIR': str(library)})
    assert path == str(library / 'Mine.3dshapes' / 'a.wrl')
    # the board's own copy wins over the library's
    (board_dir / 'Mine.3dshapes' / 'a.step').write_text('ISO-10303-21;')
    path, _ = kicad.resolve('Mine.3dshapes/a.wrl', str(board_dir), str(library), {})
    assert path == str(board_dir / 'Mine.3dshapes' / 'a.wrl')
    # in neither: the board's, which the part's refusal says is missing from both
    path, _ = kicad.resolve('Other.3dshapes/b.wrl', str(board_dir), str(library), {})
    assert path == str(board_dir / 'Other.3dshapes' / 'b.wrl')
    fp = kicad.Footprint(reference='L1', library='L:L', kind='through_hole', side='top',
                         models=(kicad.Model(path='Other.3dshapes/b.wrl', line=9),), line=7)
    [part] = board_parts([fp], str(board_dir), str(library), {})
    assert part.status == REFUSED
    missing = board_dir / 'Other.3dshapes' / 'b.wrl'
    assert part.reason == (f"its model {missing} does not exist, nor under the 3D library's "
                           'folder (board line 9)')


def test_parts_cut_side_by_side_are_in_the_cache_when_read_in_turn(tmp_path, monkeypatch):
    # the pool's processes are spawned with this environment: the same cache
    monkeypatch.setenv('PICK_SIM_CACHE', str(tmp_path / 'cache'))
    parts = os.path.join(os.path.dirname(__file__), '..', 'config', 'parts')
    files = [os.path.join(parts, 'to220_kicad.yaml')]
    (tmp_path / 'broken.yaml').write_text('part: {model: mesh, mesh: none.step}\n')
    # a file that does not read is left to its reading in turn, which names its error
    cut_side_by_side(files + [str(tmp_path / 'broken.yaml')], 2)

    cut_again = []
    monkeypatch.setattr(pieces, '_decompose', lambda *a: cut_again.append(a) or [])
    for path in files:
        assert len(geometry(part_of(path)).primitives) > 1
    assert not cut_again        # every piece came from the cache the pool filled
    with pytest.raises(InvalidArgument):
        part_of(str(tmp_path / 'broken.yaml'))


def test_bad_board_keys_are_named(tmp_path):
    with pytest.raises(InvalidArgument) as err:
        load_board(_board_file(tmp_path, boards_per_hour=0))
    assert err.value.field == 'board.boards_per_hour'
    with pytest.raises(InvalidArgument) as err:
        load_board(_board_file(tmp_path, models=tmp_path / 'nowhere'))
    assert err.value.field == 'board.models' and 'is not a folder' in err.value.rule
    with pytest.raises(InvalidArgument) as err:
        load_board(_board_file(tmp_path, pcb=tmp_path / 'none.kicad_pcb'))
    assert err.value.field == 'board.pcb' and 'cannot be read' in err.value.rule
    data = yaml.safe_load(open(_board_file(tmp_path)))
    data['requirements']['parts_per_hour'] = 60
    with pytest.raises(InvalidArgument) as err:
        expand(data, str(tmp_path / 'b.yaml'))
    assert err.value.field == 'requirements.parts_per_hour'
    data = yaml.safe_load(open(_board_file(tmp_path)))
    data['id'] = '../elsewhere'
    with pytest.raises(InvalidArgument) as err:       # its id names files and folders
        expand(data, str(tmp_path / 'b.yaml'))
    assert err.value.field == 'id'
    with pytest.raises(InvalidArgument) as err:       # a board file read as one part's file
        experiment_file.load(_board_file(tmp_path))
    assert err.value.field == 'board' and 'part by part' in err.value.rule


def test_the_diode_body_lies_off_its_mass_centre_and_gets_a_grasp():
    from pick_common.parts.geometry import build_part
    from pick_common.parts.spec import PartSpec
    from pick_validity.grasp_proposals import propose
    step = os.path.join(MODELS, 'Diode_THT.3dshapes', 'D_DO-35_SOD27_P7.62mm_Horizontal.step')
    part = build_part(PartSpec(model='mesh', mesh_path=step, mass=solid_mass(step).mass))
    (found,) = propose(part)
    point = np.array(found.grasp.grasp_point) * 1000
    assert point[2] > part.mass_centre[2] * 1000 + 0.1      # above the mass centre
    assert found.grasp.closing_axis == (0.0, 1.0, 0.0)
    assert 1.5 < found.width * 1000 < 2.1                   # across the 2 mm glass body


def test_a_disc_capacitor_with_no_flat_faces_and_no_round_body_gets_grasps_across_its_axes():
    from pick_common.parts.geometry import build_part
    from pick_common.parts.spec import PartSpec
    from pick_validity.grasp_proposals import propose
    step = os.path.join(MODELS, 'Capacitor_THT.3dshapes', 'C_Disc_D4.7mm_W2.5mm_P5.00mm.step')
    part = build_part(PartSpec(model='mesh', mesh_path=step, mass=solid_mass(step).mass))
    found = propose(part)
    assert found
    # across the disc's 2.5 mm thickness (y) and across its 4.7 mm face, at the mass centre
    widths = sorted({round(p.width * 1000, 1) for p in found})
    assert widths[0] == pytest.approx(2.3, abs=0.3) and widths[-1] < 5.0
    assert all(np.allclose(p.grasp.grasp_point, np.round(part.mass_centre, 5)) for p in found)


@pytest.mark.parametrize('tray, counts', [([120, 100, 20], (10, 70)), ([100, 80, 16], None)])
def test_a_sweep_whose_last_count_does_not_fit_runs_on_the_counts_that_do(tmp_path, tray,
                                                                          counts):
    # the terminal block (1,268 mm^3): 75 fit a 120 x 100 x 20 mm tray within the packing
    # limit 0.4, so the cell's sweep of 10..100 runs on 10..70 (70 + its margin 5 fit), and
    # the feeder reading its range still runs; in a 100 x 80 x 16 mm tray 40 fit: 10..35 are
    # fewer than the 4th-order fit's 5 counts, and the sweep is left out with its feeders
    # (5 boards an hour: a refill of 80 fits the bin, which stays)
    cell = yaml.safe_load(open(os.path.join(BOARDS, '..', 'board_cell.yaml')))
    cell['board'] = {'pcb': os.path.abspath(PCB), 'models': os.path.abspath(MODELS),
                     'boards_per_hour': 5}
    cell['tray_mm'] = tray
    path = tmp_path / 'cell.yaml'
    path.write_text(yaml.safe_dump(cell))
    files = write_parts(load_board(str(path)), str(tmp_path / 'parts'))
    file, left = settle(files['Altech_AK300_1x02_P5.00mm_45-Degree'])
    sweeps = {e.id: e.counts for e in file.experiments if e.id.startswith('sweep')}
    if counts is None:
        assert not sweeps and {e.id for e in file.experiments} == {
            'emptying', 'emptying_station', 'emptying_cup'}
        assert 'at most 40 within' in left['sweep'] and left['feeder'] == 'it names sweep'
        return
    assert sweeps == {s: tuple(range(counts[0], counts[1] + 1, 10))
                      for s in ('sweep', 'sweep_cup') if s in sweeps} and 'sweep' in sweeps
    assert 'feeder' in {e.id for e in file.experiments} and 'sweep' not in left
    text = open(files['Altech_AK300_1x02_P5.00mm_45-Degree']).read()
    assert '# sweep: counts.last 100 cut to 70: at most 75 of these parts fit' in text


def test_the_built_in_cell_leaves_out_for_a_part_what_cannot_run_and_says_why(tmp_path):
    cell = yaml.safe_load(open(os.path.join(BOARDS, '..', 'board_cell.yaml')))
    cell['board'] = {'pcb': os.path.abspath(PCB), 'models': os.path.abspath(MODELS),
                     'boards_per_hour': 60}
    path = tmp_path / 'cell.yaml'
    path.write_text(yaml.safe_dump(cell))
    board = load_board(str(path))
    files = write_parts(board, str(tmp_path / 'parts'))
    # a refill of terminal blocks (60 boards an hour x 4 a board x 4 h: 960) does not fit the
    # 100 x 150 x 18 mm bin: its emptying is left out,
    # with the station's that names it; the table and the cup still run
    # each part's bins and feeder hold its own refill; a `parts` the file gives stays
    one = yaml.safe_load(board.files['CP_Radial_D10.0mm_P5.00mm'])         # C1, one a board
    assert {e['id']: e.get('parts') for e in one['experiments']
            if e['type'] != 'table_sweep'}['emptying'] == 60 * 1 * 4
    cell['experiments'][2]['parts'] = 50
    path.write_text(yaml.safe_dump(cell))
    given = yaml.safe_load(load_board(str(path)).files['CP_Radial_D10.0mm_P5.00mm'])
    assert given['experiments'][2]['parts'] == 50 and given['experiments'][1]['parts'] == 240
    file, left = settle(files['Altech_AK300_1x02_P5.00mm_45-Degree'])
    assert '960 parts do not fit' in left['emptying']
    assert left['emptying_station'] == 'it names emptying'
    assert {e.id for e in file.experiments} >= {'sweep', 'feeder'}
    assert 'left out for this part' in open(files['Altech_AK300_1x02_P5.00mm_45-Degree']).read()
    # its run's verdicts: the bin its refill does not fit was not analysed, so it reads as
    # left out (with why below the table), not as a verdict
    # a gripper left out for a part (the disc's cup) has no option in its run: out too
    lines = answer(board, {}, {'Altech_AK300_1x02_P5.00mm_45-Degree': [
        ('static bin', 'not analysed', 'no bin_emptying experiment in the file'),
        ('vibrating table', 'FEASIBLE', 'ok'), ('vibrating table, gripper cup', 'UNDECIDED',
                                                'runs straddle')],
        'C_Disc_D4.7mm_W2.5mm_P5.00mm': [('static bin', 'NOT FEASIBLE', '0 of 5'),
                                         ('vibrating table', 'NOT FEASIBLE', '5 of 5')]},
        {'Altech_AK300_1x02_P5.00mm_45-Degree': left,
         'C_Disc_D4.7mm_W2.5mm_P5.00mm': {'gripper cup': 'no flat patch'}})
    row = next(line for line in lines if line.startswith('  Altech'))
    assert row.split()[-4:] == ['out', 'yes', '?', '[2]']          # the best: the first feasible
    disc = next(line for line in lines if line.startswith('  C_Disc'))
    assert disc.split()[-4:] == ['no', 'no', 'out', 'none']
    assert any('emptying left out: ' in line for line in lines)
    assert any('[3] UNDECIDED: runs straddle' in line for line in lines)
    assert not any('not analysed' in line for line in lines[1:])


# Datasheet weights of five families, each of a part as supplied, with its leads' count,
# least length and diameter (mm) from the same datasheet: KiCad's model has its leads formed
# and cut to the board, so the comparison is the model's body and the datasheet's leads, of
# the leads' density (pick_common/parts/solids.py).
DATASHEETS = [
    # Comchip 1N4148-G (QW-B0050): glass DO-35, "Weight: 0.13gram", leads 26.00 mm min,
    # 0.52 mm typ (https://dtsheet.com/doc/559880/comchip-1n4148-g)
    ('Diode_THT.3dshapes/D_DO-35_SOD27_P7.62mm_Horizontal.step', 0.13, 2, 26.0, 0.52),
    # Diodes Inc. 1N4001-1N4007 (DS28002): DO-41 "0.30 grams (approx)", leads 25.40 mm min,
    # 0.71 to 0.864 mm (https://dtsheet.com/doc/260565/diodes-1n4006)
    ('Diode_THT.3dshapes/D_DO-41_SOD81_P12.70mm_Horizontal.step', 0.30, 2, 25.4, 0.787),
    # Diodes Inc. PR1501-PR1505 (DS26011 Rev. 4-2): DO-15 "Weight: 0.4 grams (approximate)",
    # leads 25.40 mm min, 0.686 to 0.889 mm
    # (https://azmanual.top/manuals/305176/diodes-pr1501_s-pr1505_s.html)
    ('Diode_THT.3dshapes/D_DO-15_P10.16mm_Horizontal.step', 0.4, 2, 25.4, 0.788),
    # Comchip 1N5400-G thru 1N5408-G (QW-BG015): DO-201AD "Weight: 1.2 grams", leads 25.40
    # mm min, 1.22 to 1.32 mm (https://dtsheet.com/doc/1434594/qw-bg015-1n5400-g-thru.-1n5408);
    # Synsemi's 1N5400-08 give 0.929 g (https://dtsheet.com/doc/712847/synsemi-1n5408),
    # Diodes Inc.'s 1N5400G-08G 1.12 g (https://pdf.datasheet.world/d7ab8e14/diodes.com/
    # 1N5404G-T.txt): the model's 0.936 g lies within 30 % of each
    ('Diode_THT.3dshapes/D_DO-201AD_P15.24mm_Horizontal.step', 1.2, 2, 25.4, 1.27),
    # Vishay 2N3904 (document 88113): TO-92 "Weight: approx. 0.18g", leads 12.5 mm min,
    # 0.55 mm max (https://dtsheet.com/doc/433575/etc-2n3904-e6)
    ('Package_TO_SOT_THT.3dshapes/TO-92.step', 0.18, 3, 12.5, 0.55),
]


@pytest.mark.parametrize('model, grams, leads, length, diameter', DATASHEETS)
def test_the_mass_from_the_model_is_within_30_percent_of_the_datasheet(model, grams, leads,
                                                                       length, diameter):
    mass = solid_mass(os.path.join(MODELS, model))
    supplied = mass.body_mass + leads * length * np.pi * (diameter / 2) ** 2 * 1e-9 \
        * LEADS[1] * 1000
    assert supplied * 1000 == pytest.approx(grams, rel=0.30)


def test_a_board_run_again_keeps_the_parts_done_with_the_same_file_and_writes_its_page(
        tmp_path):
    import argparse
    import json

    from experiment_manager.commands.boards import decided, expand_boards
    path = _board_file(tmp_path)
    args = argparse.Namespace(output=str(tmp_path / 'out'), workers=2)
    boards = []
    first = expand_boards([path], args, boards)
    assert len(first) == 4                     # the four parts with a STEP model
    assert set(boards[0].read) == set(first)   # as settle read them: run reads them no more
    part = next(p for p in first if RESISTOR.replace('.', '_') in p)
    run_dir = _a_run(tmp_path / 'out' / 'resistor_run')     # a finished run, real records
    decided(boards, part, [('vibrating table', 'FEASIBLE', 'all emptied')], run_dir)
    page = (tmp_path / 'out' / 'ecc83_board.md').read_text()
    assert '| R_Axial_DIN0207_L6.3mm_D2.5mm_P7.62mm_Horizontal | 4 | R1 R2 R3 R4 | ' \
           '**FEASIBLE** | vibrating table |' in page
    assert '](resistor_run/part.png)' in page and '## Not decided' in page
    assert (tmp_path / 'out' / 'ecc83_board.html').is_file()
    # the same board again: the resistor is kept, the other three run; its options are
    # decided again from its run's records by today's rules, not copied from the answer
    again = []
    second = expand_boards([path], args, again)
    assert part not in second and len(second) == 3
    kept = {option: (verdict, why) for option, verdict, why in again[0].decided[RESISTOR]}
    assert kept['vibrating table'][0] == 'NOT FEASIBLE' and 'fewer than' in kept[
        'vibrating table'][1]
    # a run directory that no longer reads: the part runs again
    os.remove(os.path.join(run_dir, 'iterations.csv'))
    assert part in expand_boards([path], args, [])
    # a changed file (another mass) runs the part again
    changed = _board_file(tmp_path, parts={RESISTOR: {'mass_g': 0.2}})
    assert any(RESISTOR.replace('.', '_') in p for p in expand_boards([changed], args, []))
    data = json.loads((tmp_path / 'out' / 'ecc83_board.json').read_text())
    assert {p['status'] for p in data['parts']} >= {'refused', 'not through-hole'}
    _valid_against_the_published_schema(data)


def _a_run(directory) -> str:
    """A finished run directory of a small file (2 feeder runs of 12 parts, each ended at
    its one vibration: the table NOT FEASIBLE, 12 parts fewer than a refill)."""
    from experiment_manager.analysis.results import ResultsWriter
    from experiment_manager.running.local_backend import LocalBackend
    from experiment_manager.running.scheduler import Runner
    text = ('id: kept\nseed: 3\npart: {model: radial_capacitor}\n'
            'gripper: {body_diameter_mm: 8, jaw_depth_mm: 3}\nexperiments:\n'
            '  - {id: feeder, type: feeder_emptying, iterations: 2, parts: 12, '
            'optimal_range: [4, 8], max_vibrations: 1}\n')
    file = experiment_file.parse(text, str(directory) + '.yaml')
    with LocalBackend() as backend, ResultsWriter(str(directory), file.text) as sink:
        Runner(file, [backend], sink).run()
    return str(directory)


def test_a_part_an_earlier_board_run_left_interrupted_resumes_in_its_run_directory(tmp_path):
    """A board run cut in a part's run: the board run again resumes that run directory (the
    newest of the part's file that holds iterations; its summary.json, written after each
    experiment, says nothing), losing at most the iterations in flight, where it ran the part
    anew."""
    import argparse

    from experiment_manager.commands import run
    path = _board_file(tmp_path)
    out = tmp_path / 'out'

    def goals(adaptive: bool = False) -> dict:
        args = argparse.Namespace(experiment_files=[path], resume=None, output=str(out),
                                  iterations=None, adaptive=adaptive, board=None, boards=[],
                                  workers=2)
        return next(g for g, _, given, _ in run._goals(args, temporary)
                    if RESISTOR.replace('.', '_') in given)

    def run_dir(name: str, text: bytes, iterations: bool = True):
        d = out / name
        d.mkdir()
        (d / 'experiment.yaml').write_bytes(text)
        (d / 'summary.json').write_text('{}')      # as after the run's first experiment
        if iterations:
            (d / 'iterations.csv').write_text('experiment,group,iteration\n')
        return d

    temporary = []
    first = goals()
    assert not first.resume and first.output_dir == str(out)
    with open(first.experiment_file, 'rb') as f:
        text = f.read()
    file_id = yaml.safe_load(text)['id']
    cut = run_dir(f'{file_id}_20261130-010000', text)
    run_dir(f'{file_id}_20261130-020000', text, iterations=False)     # newer, no iteration
    run_dir(f'{file_id}_20261130-030000', text + b'# changed\n')      # newer, another file
    run_dir(f'other_{file_id}_20261130-040000', text)                  # another part's id
    again = goals()
    assert again.resume and again.output_dir == str(cut)
    # with --adaptive the run is of a reduced copy: that run of the whole file is not it
    reduced = goals(adaptive=True)
    assert not reduced.resume and reduced.output_dir == str(out)
    for p in temporary:
        os.remove(p)


def _valid_against_the_published_schema(data: dict) -> None:
    import json

    import jsonschema
    with open(os.path.join(DOCS, 'board.schema.json'), encoding='utf-8') as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(data, schema, cls=jsonschema.Draft202012Validator)
    for broken in ({**data, 'colour': 'red'},
                   {**data, 'parts': [{**data['parts'][0], 'status': 'maybe'}]}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(broken, schema, cls=jsonschema.Draft202012Validator)


def test_the_published_board_schema_is_the_models():
    from experiment_manager.experiment_file.board.board_json import schema_text
    with open(os.path.join(DOCS, 'board.schema.json'), encoding='utf-8') as f:
        assert f.read() == schema_text(), (
            "docs/board.schema.json is not the model's: write it again with `python -m "
            'experiment_manager.experiment_file.board.board_json --schema docs/board.schema.json`')


def test_a_part_with_no_grasp_still_gets_its_account_and_its_sheet(tmp_path, capsys):
    from experiment_manager.commands.check import _no_grasp
    from experiment_manager.experiment_file.part import NoGrasp
    from pick_common.parts.geometry import build_part
    from pick_common.parts.spec import PartSpec
    step = os.path.join(MODELS, 'Package_TO_SOT_THT.3dshapes', 'TO-92.step')
    part = build_part(PartSpec(model='mesh', mesh_path=step, mass=solid_mass(step).mass))
    error = NoGrasp('part.grasps', 'auto', 'found no grasp: ...', part)
    _no_grasp([InvalidArgument('gripper.jaw_depth_mm', 0, 'is 0'), error],
              str(tmp_path / 'to92.yaml'), None)
    said = capsys.readouterr().out
    assert 'no grasp found; the part as the run would read it' in said
    assert 'mass centre at' in said and 'collision:' in said and 'aspects it can rest on' in said
    assert (tmp_path / 'to92_part.png').stat().st_size > 10_000


def test_an_error_in_the_keys_every_part_shares_is_the_files_not_a_part_option_left_out(
        tmp_path):
    from experiment_manager.experiment_file import InvalidFile
    data = yaml.safe_load(open(_board_file(tmp_path)))
    data['experiments'][0]['iterations'] = 0
    data['grippers'] = {'cup': {'type': 'suction', 'cup_colour': 'red'}}
    with pytest.raises(InvalidFile) as err:
        expand(data, str(tmp_path / 'b.yaml'))
    assert {e.field for e in err.value.errors} == {'experiments[0].iterations',
                                                   'grippers.cup.cup_colour'}


def test_the_board_page_says_an_option_left_out_for_a_part_and_why():
    from experiment_manager.analysis.report.board import board_markdown
    part = {'name': 'TB', 'quantity': 4, 'references': ['J1'], 'status': 'decided',
            'reason': '', 'model': 'tb.step', 'mass': '0.9 g', 'run': '', 'best': '',
            'left_out': {'emptying': '960 parts do not fit the bin'},
            'options': [{'option': 'static bin', 'verdict': 'not analysed',
                         'reason': 'no bin_emptying experiment in the file'},
                        {'option': 'vibrating table', 'verdict': 'UNDECIDED',
                         'reason': 'runs straddle'}]}
    # a second part whose cup was left out: its run has no cup option at all
    disc = {**part, 'name': 'C', 'references': ['C2'], 'left_out': {'gripper cup': 'no patch'},
            'options': [{'option': 'vibrating table', 'verdict': 'NOT FEASIBLE',
                         'reason': '5 of 5'}]}
    tb = {**part, 'options': part['options'] + [
        {'option': 'vibrating table, gripper cup', 'verdict': 'FEASIBLE', 'reason': 'ok'}]}
    page = board_markdown({'board': 'b.kicad_pcb', 'boards_per_hour': 60,
                           'parts': [tb, disc]}, '.')
    assert '| TB | 4 | J1 | **left out** | **UNDECIDED** | **FEASIBLE** | none |' in page
    assert '| C | 4 | C2 | - | **NOT FEASIBLE** | left out | none |' in page
    assert '- static bin: **left out** (below)' in page
    assert '- emptying left out: 960 parts do not fit the bin' in page
    assert 'not analysed' not in page and 'no bin_emptying' not in page


def test_a_board_check_reads_each_part_once_and_checks_every_part(tmp_path, monkeypatch,
                                                                     capsys):
    """run --check on a board: each part's file is read by `settle` (with what cannot run
    left out) and that read is the one checked: no part's file is read again."""
    from experiment_manager.commands import check as check_command
    from experiment_manager.experiment_file import loading
    parsed, in_settle = [], []
    parse = loading.parse
    monkeypatch.setattr(loading, 'parse', lambda text, path='': parsed.append(path)
                        or parse(text, path))

    def settle_counted(path):
        before = len(parsed)
        try:
            return settle(path)
        finally:
            in_settle.extend(parsed[before:])
    monkeypatch.setattr(check_command, 'settle', settle_counted)
    models = tmp_path / 'models'         # two of the four parts' models, the others refused
    shutil.copytree(MODELS, models)
    os.remove(models / 'Capacitor_THT.3dshapes' / 'CP_Radial_D10.0mm_P5.00mm.step')
    os.remove(models / 'TerminalBlock_Altech.3dshapes'
              / 'Altech_AK300_1x02_P5.00mm_45-Degree.step')
    board = _board_file(tmp_path, models=models)
    assert check_command.check([board], str(tmp_path / 'out')) == 0
    out = capsys.readouterr().out
    assert out.count('reads as a run would') == 2 and 'board: ' in out
    assert len(in_settle) >= 2 and parsed == in_settle      # nothing read outside settle
    for name in os.listdir(tmp_path / 'out'):
        if os.path.isdir(tmp_path / 'out' / name) and not name.endswith('_parts'):
            assert (tmp_path / 'out' / name / 'check.json').is_file()
