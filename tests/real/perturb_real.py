#!/usr/bin/python3
"""The real footage under other light and other cameras: how far trust holds off the clips' own.

Each case of check_real.py is copied with every frame changed one way (dimmer, brighter, a light
falling off across the frame, sensor noise, heavy JPEG), tracked with the same configs and scored
against the same reference. The configs' ranges were written for the clips as they are, so finds
may be lost (a white dot dimmed below a hand-written `v` floor is not in its range any more); what
must not appear is a marker reported found beyond the case's tolerance. This is a measurement, not
a test: its table is docs/measurements.md's "The real footage under other light".

usage: perturb_real.py --softsight PROGRAM [--change NAME ...] [--case NAME ...] [--markdown]
Changes: dim75 (levels x 0.75), dim60 (x 0.6), bright (x 1.2 + 20, clipped), gradient (x 1.0 at
the left edge falling to x 0.55 at the right), noise8 (Gaussian, sigma 8 levels), jpeg30 (JPEG at
quality 30). Needs python3-opencv and numpy. Exit status: 0 when nothing was reported beyond
tolerance, 1 otherwise, 2 on a usage error.
"""
import argparse
import copy
import glob
import importlib.util
import os
import shutil
import sys
import tempfile

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location('check_real', os.path.join(HERE, 'check_real.py'))
check_real = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(check_real)

CHANGES = ['dim75', 'dim60', 'bright', 'gradient', 'noise8', 'jpeg30']


def change_frame(image, change, rng):
    if change == 'jpeg30':
        ok, buf = cv2.imencode('.jpg', image, [cv2.IMWRITE_JPEG_QUALITY, 30])
        return cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
    levels = image.astype(np.float32)
    if change == 'dim75':
        levels *= 0.75
    elif change == 'dim60':
        levels *= 0.6
    elif change == 'bright':
        levels = levels * 1.2 + 20
    elif change == 'gradient':
        fall = np.linspace(1.0, 0.55, image.shape[1], dtype=np.float32)[None, :]
        levels *= fall[..., None] if levels.ndim == 3 else fall
    elif change == 'noise8':
        levels += rng.normal(0.0, 8.0, levels.shape).astype(np.float32)
    return np.clip(np.rint(levels), 0, 255).astype(np.uint8)


def changed_case(name, change, root):
    """Copies case `name` into root/NAME with every frame changed; returns its CASES entry."""
    case = copy.deepcopy(check_real.CASES[name])
    source = os.path.join(HERE, name)
    target = os.path.join(root, name)
    os.makedirs(os.path.join(target, 'frames'))
    for f in glob.glob(os.path.join(source, '*.yaml')) + [os.path.join(source, 'reference.csv')]:
        shutil.copy(f, target)
    rng = np.random.default_rng(7)
    if case['input'].endswith(('.mp4', '.avi', '.mkv')):
        # A video becomes numbered images from 0: softsight numbers both the same way.
        capture = cv2.VideoCapture(os.path.join(source, case['input']))
        index = 0
        while True:
            ok, frame = capture.read()
            if not ok:
                break
            cv2.imwrite(os.path.join(target, 'frames', f'{index:04d}.png'),
                        change_frame(frame, change, rng))
            index += 1
        fps = capture.get(cv2.CAP_PROP_FPS) or 30.0
        case['input'] = 'frames/%04d.png'
        if '--fps' not in case['args']:
            case['args'] = case['args'] + ['--fps', f'{fps:g}']
    else:
        for f in sorted(glob.glob(os.path.join(source, 'frames', '*'))):
            image = cv2.imread(f, cv2.IMREAD_UNCHANGED)
            cv2.imwrite(os.path.join(target, 'frames', os.path.basename(f)),
                        change_frame(image, change, rng))
    return case


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--softsight', required=True, help='the softsight program to measure')
    parser.add_argument('--change', action='append', choices=CHANGES, help='one change (repeatable)')
    parser.add_argument('--case', action='append', choices=sorted(check_real.CASES),
                        help='one case (repeatable; default: all but blender-bench, whose '
                             'render is measured under other light by tests/pbr)')
    parser.add_argument('--markdown', action='store_true', help='print the measurements table')
    a = parser.parse_args()
    program = os.path.abspath(a.softsight)
    if not os.access(program, os.X_OK):
        print(f'perturb_real: --softsight {a.softsight}: not an executable program', file=sys.stderr)
        return 2
    cases = a.case or [c for c in check_real.CASES if c != 'blender-bench']
    if a.markdown:
        print('| change | case | config | found | wrong (> tol) | worst |')
        print('| --- | --- | --- | --- | --- | --- |')
    any_wrong = False
    for change in a.change or CHANGES:
        for name in cases:
            with tempfile.TemporaryDirectory(prefix=f'softsight_perturb_{change}_') as root:
                case = changed_case(name, change, root)
                _, results = check_real.run_case(program, name, case, None, root)
            for s in results:
                if 'failed' in s:
                    print(f"FAIL {change} {name} {s['config']}: {s['failed']}")
                    any_wrong = True
                    continue
                worst = (f"{s['worst'][0]:.1f} px ({s['worst'][2]}, frame {s['worst'][1]})"
                         if s['wrong'] else '-')
                any_wrong = any_wrong or s['wrong'] > 0 or s['false'] > 0
                if a.markdown:
                    print(f"| {change} | {name} | {s['config']} | {s['found']}/{s['visible']} = "
                          f"{s['rate']:.1f} % | {s['wrong']} (> {s['tol']:g} px) | {worst} |")
                else:
                    print(f"{'WRONG' if s['wrong'] or s['false'] else 'ok'} {change} {name} "
                          f"{s['config']}: found {s['found']}/{s['visible']} ({s['rate']:.1f} %), "
                          f"wrong {s['wrong']}, reported where absent {s['false']}, worst {worst}",
                          flush=True)
    return 1 if any_wrong else 0


if __name__ == '__main__':
    sys.exit(main())
