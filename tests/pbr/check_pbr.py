#!/usr/bin/python3
"""Physically based scenes in the test suite: this project's own Blender renders with exact truth.

Each scene below (tests/pbr/<scene>/, made by scripts/pbr/render.sh; CI does not render) is tracked
with every config a user would write for it (`softsight track`, as a user runs it) and scored
against its truth.csv (frame, marker, x, y, visible, visibility: the projection of each marker's
top-face centre; visible = at least half of the top face seen). A config passes when no marker is
reported found farther than the tolerance (1.5 px) from the truth, none is reported found while
less than half visible, and it finds at least its floor of the visible marker-frames. The floors
are the found rates measured when they were set, rounded down: a change that loses finds shows
here; one that gains them should raise the floor.

A config marked `known` fails today for a reason the tracker has to fix (not the scene): it is
measured and reported (KNOWN instead of FAIL) but does not fail the test. When the tracker is
fixed, remove the mark: the tolerance is never relaxed instead.

usage: check_pbr.py --softsight PROGRAM [--scene NAME ...] [--markdown] [--keep DIR] [--box-margins M,...]
  --markdown  prints a table of the measurements instead of the log lines
  --keep DIR  keeps each config's CSV and log in DIR/SCENE/
  --box-margins 0,4,12  instead: the zncc config with each box re-drawn around its marker's
              frame-0 outline grown by each margin (0: tight); every box must be accepted and no
              report may be wrong or made while covered (issue 43: boxes as people drag them)
Exit status: 0 when every scene passes, 1 otherwise, 2 on a usage error.
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
TOL = 1.5   # px: a report farther than this from the truth is wrong (issue 43)
# A found position's sigma (<marker>_sigma_px, per axis) must cover its error: at least this share
# of the found marker-frames within 3 sigma along both axes, none beyond 5 (renderer truth has
# no error of its own).
WITHIN_3_SIGMA_FLOOR = 99.0

# scene: what it shows, and per config: (config file, floor of found visible marker-frames in %,
# None or why it is known to fail today). The input is the scene's video.avi or video.mp4.
CASES = {
    'bench': dict(
        what='ordinary bench, cold light from the front, pegboard, MJPG',
        configs=[('pick', 99.0, None),
                 # 19 marker-frames were 1.5-2.5 px off before the template's blob was measured in
                 # the marker's chromaticity (the gray blob took in the dome's shaded flank)
                 ('zncc', 99.0, None)]),
    'side': dict(
        what='dim warm side light, highlights on the domes, MJPG',
        # pick found nothing here (0 %) until the contrast was judged per quarter of the ring, and
        # lost the dim blue dome in 4 frames until it was judged in chromaticity too
        configs=[('pick', 99.0, None),
                 # every report was 2-4.5 px off (median 2.7 px) before the chromaticity blob: the
                 # side light's shading pulled the gray blob towards the lit flank
                 ('zncc', 99.0, None)]),
    'distractors': dict(
        what='red screwdriver, red, green and blue caps and parts of the markers\' colours in view',
        # zncc: 93.5 % before a match whose core shows the marker's colour was accepted down to
        # a ZNCC of 0.7 (the moving green, 0.72-0.79 in gray)
        # pick: green 34 of 36 (`covered`) until a notch bitten by the dome's highlight at its
        # rim no longer counted as a cover (the blob's hull is whole, a cover cuts the hull too)
        configs=[('pick', 99.0, None),
                 ('zncc', 99.0, None)]),
    'finger': dict(
        what='a finger covers the middle marker for 10 frames',
        # pick: green (fully visible, never covered) was `lost` in 18 of 36 frames until the
        # contrast was judged in chromaticity too (its speckled surroundings spread the levels);
        # 0 of 36, and blue 1 of 24, before the contrast was judged per quarter of the ring.
        configs=[('pick', 99.0, 'pick reports green 1.67 px off in frame 2 (sigma 0.86 px): under '
                                'the top light the hue mask of the dome sits 1.0-1.4 px above its '
                                'apex, and the speckled ring moves the soft centroid further there'),
                 ('zncc', 98.0, None)]),
    'fastblur': dict(
        what='fast bend (tip up to 23 px a frame), motion blur, H.264',
        # pick: the blurred tip 1.3-2.0 px low in 3 frames until the soft centroid took in the
        # pale fringe beyond its band (the green range's floor cut the dome's lit top off)
        configs=[('pick', 99.0, None),
                 # zncc: 89.8 % before the colour of the match's core counted as evidence (the
                 # blurred tip scores 0.72-0.79 in gray)
                 ('zncc', 99.0, None)]),
    'wedge': dict(
        what='4-segment wedge, 5 markers (red, yellow, green, blue, magenta) on a wooden bench, from above',
        # zncc: magenta was lost in 17 of 36 frames while the last segment turns 80 degrees
        # against its template (its box holds the segment's edges, which turn with it), until a
        # followed match with the marker's blob at it passed 0.2 below min_zncc
        configs=[('pick', 99.0, None),
                 ('zncc', 99.0, None)]),
    'whitedots': dict(
        what='white domed dots on a dark actuator',
        configs=[('achromatic', 99.0, None), ('pick', 99.0, None), ('zncc', 99.0, None)]),
    'blackdots': dict(
        what='flat black ink dots on the milky actuator, warm side light, rib shadows as dark',
        configs=[('achromatic', 99.0, None), ('pick', 99.0, None), ('zncc', 99.0, None)]),
    'mat': dict(
        what='orange, cyan and purple markers on a green cutting mat with a white grid, from above',
        configs=[('pick', 99.0, None), ('zncc', 99.0, None)]),
    'hd': dict(
        what='1280x720 H.264, the bench, a fast blurred bend to 110 deg',
        # Twice VGA's pixels per mm: a dome's top face centre lies 0.6-1.0 px from what the
        # camera shows of it at rest (0.2-0.4 px on `bench`), and up to 2 px in the bent pose,
        # where the panel's light whitens the top of the tip's dome (as on `pale`). Every
        # reported sigma covers it (100 % within 3 sigma).
        configs=[('pick', 99.0, 'pick reports 6 of 108 finds 1.5-2.3 px off (green in the bent '
                                'pose, frames 12-21), within 3 sigma: at 1280x720 the top face '
                                'centre of a lit dome lies 1-2 px from its visible centre'),
                 ('zncc', 99.0, 'zncc reports 7 of 108 finds 1.5-2.5 px off (green in the bent '
                                'pose), within 3 sigma, as pick')]),
    'pale': dict(
        what='pale (pastel) glossy domes with sharp highlights',
        # The front light whitens each dome's upper part (saturation 10-40, the bench's 0-13 with
        # noise): every colour rule leaves it out, or half in, and the centre of what is left
        # lies 1-2.5 px below the apex. Pick's floor now drops towards the paler surroundings
        # (saturation 18-22 instead of 40): found 69 -> 105 of 108, wrong 53 -> 23.
        configs=[('pick', 96.0, 'pick reports 23 of 105 finds 1.5-2.5 px below the apex (green '
                                'in 20; 53 of 69 before the saturation floor followed the pale '
                                'surroundings): the light whitens the upper part of each pale dome'),
                 ('zncc', 99.0, 'zncc reports 58 of 108 finds 1.5-2.2 px below the apex (the '
                                'whitened upper part of each dome is left out of its blob)')]),
    'stickers': dict(
        what='flat elongated stickers (2:1) turning with the tip, warm side light',
        # pick: blue in frame 13 reported `covered` while in full view (and red in frame 11 until
        # the cover test's tolerance scaled with the sticker's enclosing circle, not its area)
        configs=[('pick', 99.0, None), ('zncc', 99.0, None)]),
    'hard': dict(
        what='everything at once: dim warm side light, distractors, a finger, a fast blurred bend',
        configs=[('pick', 99.0, None),
                 # zncc: green refused in 2 frames as it came out from behind the finger until a
                 # marker coasting for a while (blue, behind it too) no longer claimed every place
                 # its grown gate held that its tracker did not list
                 ('zncc', 99.0, None)]),
    'wedgehard': dict(
        what='the 5-colour wedge from above, warm side lamp, a finger over its second marker, fast blurred bend',
        # Seen from above, each dome is shaded on one side by the low lamp; the colour rules
        # keep the lit side, so a fast, blurred marker comes out 1.3-1.7 px towards the lamp.
        configs=[('pick', 99.0, 'pick reports 2 of 180 finds 1.6 px off (magenta, frame 13; red, '
                                'frame 18), within 3 sigma: the low side lamp shades one flank of '
                                'each dome'),
                 # zncc lost red for 9 frames while the finger's shadow lay over its surroundings
                 # (the gray match 0.45-0.50) until a followed match was accepted in
                 # log-chromaticity, which a shadow leaves unchanged, and reported it 1.55 px off
                 # in frame 12, as the shadow reached the dome and cut its blob, until such a
                 # frame was placed in log-chromaticity too.
                 ('zncc', 99.0, 'boxes drawn tight (0 px margin) report 3 of 180 finds 1.5-1.9 px '
                                'off and 12 px margins 1 (1.5 px); 3 and 12 px margins lose 14-17 % '
                                'of the finds: the low lamp shades each dome on one side')]),
    'darkdomes': dict(
        what='orange, cyan and purple domes on a dark actuator, dim warm side lamp, fast blurred bend',
        # The lamp low on the right lights each dome's right flank; its left one is as dark as the
        # actuator, so what a camera (and a person) sees of the dome is centred 1.5-2 px right of
        # the apex. (Pick took the orange dome for a white dot until a pigment's saturation ruled
        # out a tinted white: 2-2.8 px off, 1 beyond 5 sigma.)
        configs=[('pick', 99.0, 'pick reports 97 of 108 finds 1.5-3.4 px right of the apex, 92.6 % '
                                'within 3 sigma: the dark actuator hides each dome\'s shaded flank'),
                 ('zncc', 99.0, 'zncc reports 29 of 108 finds 1.5-1.8 px right of the apex (within '
                                '3 sigma), as pick')]),
    'wood960': dict(
        what='yellow, blue and red domes on wood from above, ceiling panel, 960x540 H.264',
        configs=[('pick', 99.0, None),
                 # zncc reported 3 of 108 finds 1.5-1.65 px off (yellow, the wood's hue, 1.1 px
                 # above the apex in every frame) until a tie in how well the marker stands out in
                 # gray levels and in chromaticity went to the chromaticity, which shading leaves
                 ('zncc', 99.0, None)]),
}


def scene_video(folder):
    """The scene's video file name: video.avi, or video.mp4 (the H.264 scene)."""
    return 'video.avi' if os.path.exists(os.path.join(folder, 'video.avi')) else 'video.mp4'


def config_markers(path):
    """The marker names of a config in their order, and its triple or chain (a small reader for
    the configs written by scripts/pbr/post.py and `softsight pick`, not a YAML parser)."""
    names, groups = [], {}
    with open(path) as f:
        for line in f:
            m = re.match(r'\s*-\s*name:\s*(\S+)', line)
            if m:
                names.append(m.group(1))
            m = re.match(r'(triple|chain):\s*\[(.*)\]', line)
            if m:
                groups[m.group(1)] = [n.strip() for n in m.group(2).split(',')]
    # a chain, when given, holds every marker (`pick` writes both for five markers)
    return names, groups.get('chain', groups.get('triple', []))


def angle_at(a, b, c):
    d = math.degrees(math.atan2(a[1] - b[1], a[0] - b[0]) - math.atan2(c[1] - b[1], c[0] - b[0])) % 360
    return min(d, 360 - d)


def score(track_csv, truth_csv, name_map, group, tolerance=TOL):
    """Scores one CSV against the truth: per marker-frame found/visible, wrong (> tolerance, px),
    reported while covered (found with visibility < 0.5), distances; the angle error at each inner
    marker of the triple or chain in the frames where it and its two neighbours are found."""
    with open(track_csv, newline='') as f:
        rows = {int(r['frame']): r for r in csv.DictReader(f)}
    with open(truth_csv, newline='') as f:
        truth = list(csv.DictReader(f))
    by_frame = {}
    for r in truth:
        by_frame.setdefault(int(r['frame']), {})[r['marker']] = r
    s = dict(visible=0, found=0, wrong=0, covered=0, reported_covered=0, errors=[], worst=None,
             angle=[], per_marker={}, within_3_sigma=0, beyond_5_sigma=0)
    for r in truth:
        if r['marker'] not in name_map:  # a marker the config does not hold (init's)
            continue
        name = name_map[r['marker']]
        row = rows.get(int(r['frame']))
        found = row is not None and row.get(f'{name}_found') == '1'
        pm = s['per_marker'].setdefault(r['marker'], [0, 0])
        if r['visible'] != '1':
            s['covered'] += 1
            s['reported_covered'] += found
            continue
        s['visible'] += 1
        pm[1] += 1
        if not found:
            continue
        s['found'] += 1
        pm[0] += 1
        ex, ey = float(row[f'{name}_x']) - float(r['x']), float(row[f'{name}_y']) - float(r['y'])
        d = math.hypot(ex, ey)
        s['errors'].append(d)
        normalised = max(abs(ex), abs(ey)) / float(row[f'{name}_sigma_px'])
        s['within_3_sigma'] += normalised <= 3
        s['beyond_5_sigma'] += normalised > 5
        if d > tolerance:
            s['wrong'] += 1
            if s['worst'] is None or d > s['worst'][0]:
                s['worst'] = (d, r['frame'], r['marker'])
    inverse = {v: k for k, v in name_map.items()}
    column = (lambda k: 'angle_deg') if len(group) == 3 else (lambda k: f'angle_{group[k]}_deg')
    for frame, row in rows.items():
        tr = by_frame.get(frame, {})
        for k in range(1, len(group) - 1):
            trio = group[k - 1:k + 2]
            if row.get(column(k), '') == '' or not all(row.get(f'{n}_found') == '1' for n in trio):
                continue
            pts = [(float(tr[inverse[n]]['x']), float(tr[inverse[n]]['y'])) for n in trio]
            s['angle'].append(abs(float(row[column(k)]) - angle_at(*pts)))
    return s


def run_scene(program, name, case, keep):
    """Tracks and scores every config of one scene; returns (ok, [result per config])."""
    folder = os.path.join(HERE, name)
    video = scene_video(folder)
    with open(os.path.join(folder, 'truth.csv'), newline='') as f:
        truth_names = list(dict.fromkeys(r['marker'] for r in csv.DictReader(f)))
    out = os.path.join(keep, name) if keep else tempfile.mkdtemp(prefix=f'softsight_pbr_{name}_')
    os.makedirs(out, exist_ok=True)
    results, ok = [], True
    for cfg, floor, known in case['configs']:
        names, group = config_markers(os.path.join(folder, f'{cfg}.yaml'))
        name_map = dict(zip(truth_names, names))   # the configs list the markers in truth order
        csv_path = os.path.join(out, f'{cfg}.csv')
        if os.path.exists(csv_path):
            os.remove(csv_path)
        cmd = [program, 'track', '-c', f'{cfg}.yaml', '-i', video, '--csv', csv_path, '--quiet']
        done = subprocess.run(cmd, cwd=folder, capture_output=True, text=True)
        with open(os.path.join(out, f'{cfg}.log'), 'w') as log:
            log.write(done.stdout + done.stderr)
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
            results.append(dict(config=cfg, known=known, failed=f'track exited {done.returncode}: {last}'))
            ok = ok and known is not None
            continue
        s = score(csv_path, os.path.join(folder, 'truth.csv'), name_map, group)
        s.update(config=cfg, floor=floor, known=known)
        s['rate'] = 100.0 * s['found'] / max(1, s['visible'])
        problems = []
        if s['wrong']:
            d, frame, marker = s['worst']
            problems.append(f"{s['wrong']} reported found > {TOL:g} px off (worst {d:.1f} px: "
                            f"{marker} in frame {frame})")
        if s['reported_covered']:
            problems.append(f"{s['reported_covered']} reported found while less than half visible")
        if s['rate'] < floor:
            problems.append(f"found {s['rate']:.1f} % < floor {floor:g} %")
        s['sigma_rate'] = 100.0 * s['within_3_sigma'] / max(1, s['found'])
        if s['found'] and s['sigma_rate'] < WITHIN_3_SIGMA_FLOOR:
            problems.append(f"{s['sigma_rate']:.1f} % of the found positions within 3 sigma "
                            f"< {WITHIN_3_SIGMA_FLOOR:g} %")
        if s['beyond_5_sigma']:
            problems.append(f"{s['beyond_5_sigma']} found positions beyond 5 sigma")
        s['problems'] = problems
        ok = ok and (not problems or known is not None)
        results.append(s)
        if not keep:
            os.remove(csv_path)
    if not keep:
        for f in os.listdir(out):
            os.remove(os.path.join(out, f))
        os.rmdir(out)
    return ok, results


def track_and_judge(program, folder, video, cfg, csv_path, truth_names, known, label, failure,
                    with_median=False):
    """The tail the box-margin and click-offset sweeps share: tracks the scene's video with the
    config `cfg` into `csv_path`, scores it and words the verdict, `label` naming the case. Any
    report beyond the tolerance or while covered fails, or is KNOWN where the scene's config is
    known to fail (`known`, from CASES); a track that exits non-zero fails, worded by `failure`
    ({code}: its exit status, {last}: its last message). Returns (ok, line)."""
    done = subprocess.run([program, 'track', '-c', cfg, '-i', video, '--csv', csv_path, '--quiet'],
                          cwd=folder, capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
        return False, f'FAIL {label}: ' + failure.format(code=done.returncode, last=last)
    names, group = config_markers(cfg)
    s = score(csv_path, os.path.join(folder, 'truth.csv'), dict(zip(truth_names, names)), group)
    bad = s['wrong'] or s['reported_covered']
    worst = f" (worst {s['worst'][0]:.1f} px: {s['worst'][2]} in frame {s['worst'][1]})" if s['worst'] else ''
    verdict = ('KNOWN' if known is not None else 'FAIL') if bad else 'ok'
    line = (f"{verdict} {label}: found {s['found']}/{s['visible']} "
            f"({100.0 * s['found'] / max(1, s['visible']):.1f} %), wrong (> {TOL:g} px) "
            f"{s['wrong']}{worst}, reported while covered {s['reported_covered']}")
    if with_median:
        line += f", median {median(s['errors']):.2f} px"
    return not bad or known is not None, line


def box_margins(program, name, margins):
    """Template boxes as people drag them: each marker's frame-0 outline (scene.json) grown by each
    margin (0: tight around the marker), in the scene's zncc config. Every box must be accepted and
    track with no report beyond the tolerance and none while covered. Returns (ok, lines)."""
    folder = os.path.join(HERE, name)
    video = scene_video(folder)
    with open(os.path.join(folder, 'scene.json')) as f:
        outlines = {m['name']: m['bbox'] for m in json.load(f)['markers']}
    with open(os.path.join(folder, 'truth.csv'), newline='') as f:
        truth_names = list(dict.fromkeys(r['marker'] for r in csv.DictReader(f)))
    with open(os.path.join(folder, 'zncc.yaml')) as f:
        config = f.read()
    known = dict((c, k) for c, _, k in CASES[name]['configs']).get('zncc')
    ok, lines = True, []
    with tempfile.TemporaryDirectory(prefix=f'softsight_pbr_{name}_') as out:
        for margin in margins:
            text = config
            for marker, (x, y, w, h) in outlines.items():
                text = re.sub(r'(name: %s\n\s*method: zncc\n\s*template: \{frame: 0, rect: )\[[^\]]*\]' % marker,
                              r'\g<1>[%d, %d, %d, %d]' % (x - margin, y - margin, w + 2 * margin, h + 2 * margin),
                              text)
            cfg, csv_path = os.path.join(out, f'm{margin}.yaml'), os.path.join(out, f'm{margin}.csv')
            with open(cfg, 'w') as f:
                f.write(text)
            one_ok, line = track_and_judge(program, folder, video, cfg, csv_path, truth_names, known,
                                           f'{name} zncc boxes margin {margin} px',
                                           'refused: {last}', with_median=True)
            ok = ok and one_ok
            lines.append(line)
    return ok, lines


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float('nan')


def median(values):
    v = sorted(values)
    return v[len(v) // 2] if v else float('nan')


def click_offsets(program, name, offsets):
    """Clicks as people make them: `softsight pick --at` each marker's frame-0 centre moved by each
    offset (dx, dy px), then tracked. A pick may be refused, and a marker may go unfound (the user
    clicks again), but nothing may be reported beyond the tolerance or while covered, except where
    the scene's pick config is known to fail. Returns (ok, lines)."""
    folder = os.path.join(HERE, name)
    video = scene_video(folder)
    with open(os.path.join(folder, 'truth.csv'), newline='') as f:
        rows = list(csv.DictReader(f))
    truth_names = list(dict.fromkeys(r['marker'] for r in rows))
    first = {r['marker']: (float(r['x']), float(r['y'])) for r in rows if r['frame'] == '0'}
    known = dict((c, k) for c, _, k in CASES[name]['configs']).get('pick')
    ok, lines = True, []
    with tempfile.TemporaryDirectory(prefix=f'softsight_pbr_{name}_') as out:
        for dx, dy in offsets:
            label = f'{name} pick {dx:+d},{dy:+d} px off'
            cfg, csv_path = os.path.join(out, 'pick.yaml'), os.path.join(out, 'pick.csv')
            ats = [arg for m in truth_names
                   for arg in ('--at', f'{first[m][0] + dx:.0f},{first[m][1] + dy:.0f}')]
            done = subprocess.run([program, 'pick', '-i', video, '--frame', '0', *ats, '-o', cfg],
                                  cwd=folder, capture_output=True, text=True)
            if done.returncode != 0:
                last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
                lines.append(f'ok {label}: refused ({last[:100]})')
                continue
            one_ok, line = track_and_judge(program, folder, video, cfg, csv_path, truth_names, known,
                                           label, 'track exited {code}: {last}')
            ok = ok and one_ok
            lines.append(line)
    return ok, lines


# `softsight init` as a new user runs it on frame 0 of each scene: how many markers it must write
# (each then tracked with none reported wrong or while covered), or None where it must refuse.
INIT_EXPECTED = {
    'bench': 3, 'finger': 3, 'fastblur': 3, 'wedge': 5,
    # blue, dim under the warm side light (value 24-68): init missed it until its hue bands were
    # also searched from half the value floor
    'side': 3,
    # caps of the markers' colours in view: init will not guess which blob is the marker
    'distractors': None,
    # white dots on a colourful bench: no coloured marker, so white or black dots by gray level
    'whitedots': 3,
    # the pegboard's holes are dark dots as well, dozens of them: init will not guess
    'blackdots': None,
    'mat': 3,
    'hd': 3,
    # pastel domes (saturation 40-120) are below the finder's saturation floor (70)
    'pale': None,
    'stickers': 3,
    # the orange dome is not written: under the warm lamp its shaded flank is as dark as the
    # actuator and its lit one of the lamp's hue (a click on it is picked)
    'darkdomes': 2,
    'wood960': 3,
    # the caps of the markers' colours again: init will not guess
    'hard': None,
    'wedgehard': 5,
}


# Known to fail today, with why (the line says KNOWN and the run passes).
INIT_KNOWN = {
    'hd': '6 reports 1.5-2.3 px off (green in the bent pose), as pick',
    # (fastblur's blurred tip was 1.5-2.0 px off in 3 frames until the soft centroid took in the
    # pale fringe.)
    'darkdomes': 'cyan and purple reported 1.5-2 px right of the apex, as by pick (the dark '
                 'actuator hides each dome\'s shaded flank)',
    'wedgehard': '5 reports 1.5-1.7 px off: domes seen from above under a low side lamp, the '
                 'shaded flank or the lit one outside the written ranges',
}


def init_scene(program, name):
    """Runs init on the scene's frame 0 and tracks with what it wrote; returns (ok, line)."""
    folder = os.path.join(HERE, name)
    video = scene_video(folder)
    expected = INIT_EXPECTED[name]
    with tempfile.TemporaryDirectory(prefix=f'softsight_pbr_init_{name}_') as out:
        cfg, csv_path = os.path.join(out, 'init.yaml'), os.path.join(out, 'init.csv')
        done = subprocess.run([program, 'init', '-i', video, '-o', cfg], cwd=folder,
                              capture_output=True, text=True)
        if expected is None:
            ok = done.returncode == 2 and not os.path.exists(cfg)
            last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
            return ok, f"{'ok' if ok else 'FAIL'} {name} init: refused ({last[:120]})"
        if done.returncode != 0:
            return False, f'FAIL {name} init: exited {done.returncode}: {done.stderr.strip()[-200:]}'
        names, _ = config_markers(cfg)
        if len(names) != expected:
            return False, f'FAIL {name} init: {len(names)} markers written ({names}), expected {expected}'
        done = subprocess.run([program, 'track', '-c', cfg, '-i', video, '--csv', csv_path, '--quiet'],
                              cwd=folder, capture_output=True, text=True)
        if done.returncode != 0:
            return False, f'FAIL {name} init: track exited {done.returncode}: {done.stderr.strip()[-200:]}'
        # init names markers by colour, in its own order: each is the truth marker nearest to where
        # it was found in frame 0.
        with open(os.path.join(folder, 'truth.csv'), newline='') as f:
            start = {r['marker']: (float(r['x']), float(r['y'])) for r in csv.DictReader(f)
                     if r['frame'] == '0'}
        with open(csv_path, newline='') as f:
            first = next(csv.DictReader(f))
        name_map = {}
        for n in names:
            if first.get(f'{n}_found') != '1':
                return False, f'FAIL {name} init: {n} not found in frame 0'
            p = (float(first[f'{n}_x']), float(first[f'{n}_y']))
            truth = min(start, key=lambda m: math.hypot(start[m][0] - p[0], start[m][1] - p[1]))
            name_map[truth] = n
        s = score(csv_path, os.path.join(folder, 'truth.csv'), name_map, [])
        ok = not s['wrong'] and not s['reported_covered']
        verdict = 'ok' if ok else 'KNOWN' if name in INIT_KNOWN else 'FAIL'
        known = f' (known: {INIT_KNOWN[name]})' if verdict == 'KNOWN' else ''
        return ok or name in INIT_KNOWN, (f"{verdict} {name} init: {len(names)} markers, found "
                    f"{s['found']}/{s['visible']}, wrong (> {TOL:g} px) {s['wrong']}, reported while "
                    f"covered {s['reported_covered']}{known}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--softsight', required=True, help='the softsight program to measure')
    parser.add_argument('--scene', action='append', choices=sorted(CASES), help='one scene (repeatable)')
    parser.add_argument('--markdown', action='store_true', help='print the measurements table')
    parser.add_argument('--keep', help='keep the CSVs and logs in this folder')
    parser.add_argument('--box-margins', help='instead: ZNCC boxes drawn around each marker with these '
                        'margins (px, comma-separated; 0 = tight), each accepted and never wrong')
    parser.add_argument('--click-offsets', help='instead: `softsight pick --at` each frame-0 centre moved '
                        'by these offsets (DX,DY px; several separated by spaces or semicolons), '
                        'never wrong')
    parser.add_argument('--init', action='store_true', help='instead: `softsight init` on frame 0, '
                        'the markers it must write (or its refusal), then tracked with none wrong')
    a = parser.parse_args()
    program = os.path.abspath(a.softsight)
    if not os.access(program, os.X_OK):
        print(f'check_pbr: --softsight {a.softsight}: not an executable program', file=sys.stderr)
        return 2
    all_ok = True
    if a.init:
        for name in a.scene or list(CASES):
            ok, line = init_scene(program, name)
            all_ok = all_ok and ok
            print(line)
        return 0 if all_ok else 1
    if a.click_offsets:
        offsets = [tuple(int(v) for v in o.split(',')) for o in re.split(r'[;\s]+', a.click_offsets.strip())]
        for name in a.scene or list(CASES):
            ok, lines = click_offsets(program, name, offsets)
            all_ok = all_ok and ok
            print('\n'.join(lines))
        return 0 if all_ok else 1
    if a.box_margins:
        margins = [int(m) for m in a.box_margins.split(',')]
        for name in a.scene or list(CASES):
            ok, lines = box_margins(program, name, margins)
            all_ok = all_ok and ok
            print('\n'.join(lines))
        return 0 if all_ok else 1
    if a.markdown:
        print('| scene | config | found (floor) | per marker | wrong (> 1.5 px) | reported while covered '
              '| median / RMS px | within 3 sigma / beyond 5 | angle error median / max |')
        print('| --- | --- | --- | --- | --- | --- | --- | --- | --- |')
    for name in a.scene or list(CASES):
        ok, results = run_scene(program, name, CASES[name], a.keep)
        all_ok = all_ok and ok
        for s in results:
            mark = ' (known failing)' if s['known'] else ''
            if 'failed' in s:
                print(f"{'KNOWN' if s['known'] else 'FAIL'} {name} {s['config']}: {s['failed']}{mark}")
                continue
            angle = (f"{median(s['angle']):.2f} / {max(s['angle']):.2f} deg ({len(s['angle'])})"
                     if s['angle'] else '-')
            spread = f"{median(s['errors']):.2f} / {rms(s['errors']):.2f}" if s['errors'] else '-'
            per = ', '.join(f'{m} {f}/{v}' for m, (f, v) in s['per_marker'].items())
            if a.markdown:
                print(f"| {name} | {s['config']}{mark} | {s['found']}/{s['visible']} = {s['rate']:.1f} % "
                      f"({s['floor']:g} %) | {per} | {s['wrong']} | {s['reported_covered']} of "
                      f"{s['covered']} | {spread} | {s['sigma_rate']:.1f} % / {s['beyond_5_sigma']} "
                      f"| {angle} |")
            else:
                verdict = ('KNOWN' if s['known'] else 'FAIL') if s['problems'] else 'ok'
                print(f"{verdict} {name} {s['config']}: found {s['found']}/{s['visible']} "
                      f"({s['rate']:.1f} %, floor {s['floor']:g} %; {per}), wrong (> {TOL:g} px) "
                      f"{s['wrong']}, reported while covered {s['reported_covered']} of {s['covered']}, "
                      f"median {median(s['errors']):.2f} px, RMS {rms(s['errors']):.2f} px, "
                      f"within 3 sigma {s['sigma_rate']:.1f} % (beyond 5: {s['beyond_5_sigma']}), "
                      f"angle error {angle}{mark}"
                      + ''.join(f'\n    {p}' for p in s['problems'])
                      + (f"\n    known: {s['known']}" if s['known'] and s['problems'] else ''))
    return 0 if all_ok else 1


if __name__ == '__main__':
    sys.exit(main())
