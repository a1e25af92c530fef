#!/usr/bin/python3
"""The physically based scenes under other light and other cameras: does trust hold off our renders?

Each scene of check_pbr.py is copied with every frame changed one way (dimmer, brighter, a warm or
a cold white balance, light falling off across the frame, sensor noise, heavy JPEG, a smaller
sensor), then set up as a user would on the changed footage (`softsight pick --at` each marker's
frame-0 centre, rounded to whole pixels; the scene's ZNCC boxes, scaled with the frame), tracked
and scored against the same truth (scaled with the frame). Finds may be lost (a dim blue dome may
fall below what a pick can separate from the bench); what must not appear is a marker reported
found beyond the tolerance (1.5 px, scaled with the frame) or while covered. This is a
measurement, not a test (the suite runs check_pbr.py on the scenes as rendered): its table is
docs/measurements.md's "The rendered scenes under other light and other cameras".

usage: perturb_pbr.py --softsight PROGRAM [--change NAME ...] [--scene NAME ...] [--case SCENE:CHANGE ...]
                      [--config pick|zncc ...] [--floor PERCENT] [--markdown] [--keep DIR]
Changes: dim60 (levels x 0.6), bright (x 1.2 + 20, clipped), warm (red x 1.15, blue x 0.75: a
tungsten lamp without white balance), cold (red x 0.8, blue x 1.15), gradient (x 1.0 at the left
edge falling to x 0.55 at the right), noise8 (Gaussian, sigma 8 levels), jpeg30 (JPEG at quality
30), scale75 (the frame resized to 0.75 of its size, as a lower-resolution camera). Needs
python3-opencv and numpy. With --floor (the suite's `pbr_scene.perturbed`, on the cases it names),
a refused pick or template box, or a config finding less than that share of the visible
marker-frames, fails too; without it a refusal (with its reason) is no failure.
Exit status: 0 when nothing was reported beyond tolerance or while covered (and every floor was
met), 1 otherwise, 2 on a usage error.
"""
import argparse
import csv
import importlib.util
import os
import re
import subprocess
import sys
import tempfile

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def _load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


check_pbr = _load('check_pbr', os.path.join(HERE, 'check_pbr.py'))
# The changes the real footage gets (dim60, bright, gradient, noise8, jpeg30) are its own.
perturb_real = _load('perturb_real', os.path.join(HERE, '..', 'real', 'perturb_real.py'))

CHANGES = ['dim60', 'bright', 'warm', 'cold', 'gradient', 'noise8', 'jpeg30', 'scale75']


def scale_of(change):
    return 0.75 if change == 'scale75' else 1.0


def change_frame(image, change, rng):
    """One frame (BGR) changed one way: a colour cast or a smaller sensor here, the rest as
    perturb_real.py changes the real footage."""
    if change == 'scale75':
        size = (round(image.shape[1] * 0.75), round(image.shape[0] * 0.75))
        return cv2.resize(image, size, interpolation=cv2.INTER_AREA)
    if change in ('warm', 'cold'):
        gains = [0.75, 1.0, 1.15] if change == 'warm' else [1.15, 1.0, 0.8]  # B, G, R
        levels = image.astype(np.float32) * np.array(gains, np.float32)
        return np.clip(np.rint(levels), 0, 255).astype(np.uint8)
    return perturb_real.change_frame(image, change, rng)


def to_scaled(v, s):
    """A pixel coordinate (pixel centres at integers) in a frame resized by s."""
    return (v + 0.5) * s - 0.5


def changed_scene(name, change, root):
    """Writes scene `name` changed one way into root/: the frames as a lossless PNG sequence (the
    change is the only loss on top of the scene's own codec), truth.csv scaled with the frame, and
    zncc.yaml with its boxes scaled. Returns the folder."""
    folder = os.path.join(HERE, name)
    target = os.path.join(root, f'{name}_{change}')
    os.makedirs(os.path.join(target, 'frames'))
    rng = np.random.default_rng(1)
    cap = cv2.VideoCapture(os.path.join(folder, check_pbr.scene_video(folder)))
    index = 0
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        cv2.imwrite(os.path.join(target, 'frames', f'{index:04d}.png'), change_frame(frame, change, rng))
        index += 1
    s = scale_of(change)
    with open(os.path.join(folder, 'truth.csv'), newline='') as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r['x'], r['y'] = f"{to_scaled(float(r['x']), s):.4f}", f"{to_scaled(float(r['y']), s):.4f}"
    with open(os.path.join(target, 'truth.csv'), 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    def scaled_rect(m):
        x, y, w, h = (int(v) for v in m.group(2).split(','))
        x0, y0 = round(x * s), round(y * s)
        return f'{m.group(1)}[{x0}, {y0}, {round((x + w) * s) - x0}, {round((y + h) * s) - y0}]'

    with open(os.path.join(folder, 'zncc.yaml')) as f:
        zncc = re.sub(r'(rect:\s*)\[([^\]]*)\]', scaled_rect, f.read())
    with open(os.path.join(target, 'zncc.yaml'), 'w') as f:
        f.write(zncc)
    return target


def run_case(program, name, change, root):
    """Picks and tracks one changed scene; returns [(config, score or failure text)]."""
    target = changed_scene(name, change, root)
    s = scale_of(change)
    truth_csv = os.path.join(target, 'truth.csv')
    with open(truth_csv, newline='') as f:
        rows = list(csv.DictReader(f))
    truth_names = list(dict.fromkeys(r['marker'] for r in rows))
    first = {r['marker']: (float(r['x']), float(r['y'])) for r in rows if r['frame'] == '0'}
    video = os.path.join('frames', '%04d.png')
    results = []
    ats = [a for m in truth_names for a in ('--at', f'{first[m][0]:.0f},{first[m][1]:.0f}')]
    done = subprocess.run([program, 'pick', '-i', video, '--frame', '0', *ats, '-o', 'pick.yaml'],
                          cwd=target, capture_output=True, text=True)
    configs = ['zncc']
    if done.returncode == 0:
        configs.insert(0, 'pick')
    else:
        last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
        results.append(('pick', f'refused: {last[:90]}'))
    for cfg in configs:
        out = os.path.join(target, f'{cfg}.csv')
        done = subprocess.run([program, 'track', '-c', f'{cfg}.yaml', '-i', video, '--csv', out,
                               '--quiet'], cwd=target, capture_output=True, text=True)
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ['(no message)'])[-1]
            # A box refused with its reason is, like a refused pick, no wrong report.
            refused = done.returncode == 2 and 'holds no marker' in last
            results.append((cfg, f'refused: {last[:90]}' if refused
                            else f'track exited {done.returncode}: {last[:90]}'))
            continue
        names, group = check_pbr.config_markers(os.path.join(target, f'{cfg}.yaml'))
        tolerance = check_pbr.TOL * s
        sc = check_pbr.score(out, truth_csv, dict(zip(truth_names, names)), group, tolerance)
        sc['tolerance'] = tolerance
        results.append((cfg, sc))
    return results


def print_markdown(table):
    """A summary per change and config, then every run with a report beyond tolerance or refused."""
    print('| change | config | runs | found | wrong (> 1.5 px x scale) | runs with wrong reports | '
          'worst | refused or failed |')
    print('| --- | --- | --- | --- | --- | --- | --- | --- |')
    for change in CHANGES:
        for cfg in ('pick', 'zncc'):
            rows = [r for r in table if r['change'] == change and r['config'] == cfg]
            if not rows:
                continue
            scored = [r for r in rows if 'score' in r]
            found = sum(r['score']['found'] for r in scored)
            visible = sum(r['score']['visible'] for r in scored)
            wrong = sum(r['score']['wrong'] for r in scored)
            worst = max((r['score']['worst'] for r in scored if r['score']['worst']), default=None)
            worst_text = (f"{worst[0]:.2f} px ({[r['scene'] for r in scored if r['score']['worst'] == worst][0]}, "
                          f"{worst[2]})" if worst else '-')
            print(f"| {change} | {cfg} | {len(rows)} | {found}/{visible} = "
                  f"{100.0 * found / max(1, visible):.1f} % | {wrong} | "
                  f"{sum(1 for r in scored if r['score']['wrong'])} | {worst_text} | "
                  f"{len(rows) - len(scored)} |")
    print()
    print('| scene | change | config | found | wrong (> 1.5 px x scale) | worst | within 3 sigma |')
    print('| --- | --- | --- | --- | --- | --- | --- |')
    for r in table:
        if 'score' not in r:
            print(f"| {r['scene']} | {r['change']} | {r['config']} | {r['failure']} | | | |")
            continue
        sc = r['score']
        if not sc['wrong'] and not sc['reported_covered']:
            continue
        worst = f"{sc['worst'][0]:.2f} px ({sc['worst'][2]}, frame {sc['worst'][1]})"
        print(f"| {r['scene']} | {r['change']} | {r['config']} | {sc['found']}/{sc['visible']} = "
              f"{100.0 * sc['found'] / max(1, sc['visible']):.1f} % | {sc['wrong']} | {worst} | "
              f"{100.0 * sc['within_3_sigma'] / max(1, sc['found']):.1f} % |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--softsight', required=True, help='the softsight program to measure')
    parser.add_argument('--change', action='append', choices=CHANGES, help='one change (repeatable)')
    parser.add_argument('--scene', action='append', choices=sorted(check_pbr.CASES),
                        help='one scene (repeatable)')
    parser.add_argument('--case', action='append', metavar='SCENE:CHANGE',
                        help='one scene with one change (repeatable; instead of --scene/--change)')
    parser.add_argument('--config', action='append', choices=['pick', 'zncc'],
                        help='only this config (repeatable; default both)')
    parser.add_argument('--floor', type=float, help='also fail on a refused pick or a found rate '
                        'below this percentage')
    parser.add_argument('--markdown', action='store_true', help='print a table instead of log lines')
    parser.add_argument('--keep', help='keep the changed scenes, configs and CSVs in this folder')
    args = parser.parse_args()
    program = os.path.abspath(args.softsight)
    if not os.access(program, os.X_OK):
        print(f'perturb_pbr.py: --softsight {args.softsight}: not an executable', file=sys.stderr)
        return 2
    cases = [(name, change) for name in (args.scene or list(check_pbr.CASES))
             for change in (args.change or CHANGES)]
    if args.case:
        cases = []
        for c in args.case:
            name, _, change = c.partition(':')
            if name not in check_pbr.CASES or change not in CHANGES:
                print(f'perturb_pbr.py: --case {c}: not SCENE:CHANGE with a scene of check_pbr.py '
                      f'and a change of {", ".join(CHANGES)}', file=sys.stderr)
                return 2
            cases.append((name, change))
    bad = 0
    table = []
    root = args.keep or tempfile.mkdtemp(prefix='softsight_perturb_pbr_')
    os.makedirs(root, exist_ok=True)
    try:
        for name, change in cases:
            for cfg, s in run_case(program, name, change, root):
                if args.config and cfg not in args.config:
                    continue
                if isinstance(s, str):
                    # A track that exits with an error always fails; a refused pick or template
                    # box only under a floor.
                    short = s.startswith('track exited') or args.floor is not None
                    bad += short
                    line = f"{'FAIL ' if short else ''}{name} {change} {cfg}: {s}"
                    table.append(dict(scene=name, change=change, config=cfg, failure=s))
                else:
                    wrong = s['wrong'] + s['reported_covered']
                    rate = 100.0 * s['found'] / max(1, s['visible'])
                    short = args.floor is not None and rate < args.floor
                    bad += wrong + short
                    worst = (f" (worst {s['worst'][0]:.2f} px: {s['worst'][2]} in frame "
                             f"{s['worst'][1]})" if s['worst'] else '')
                    floor = f', floor {args.floor:g} %' if args.floor is not None else ''
                    line = (f"{'FAIL' if wrong or short else 'ok'} {name} {change} {cfg}: found "
                            f"{s['found']}/{s['visible']} ({rate:.1f} %{floor}), wrong "
                            f"(> {s['tolerance']:.3g} px) {s['wrong']}{worst}, reported while "
                            f"covered {s['reported_covered']}")
                    table.append(dict(scene=name, change=change, config=cfg, score=s))
                # With --markdown the table goes to stdout at the end, the progress to stderr.
                print(line, file=sys.stderr if args.markdown else sys.stdout, flush=True)
    finally:
        if not args.keep:
            subprocess.run(['rm', '-rf', root])
    if args.markdown:
        print_markdown(table)
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
