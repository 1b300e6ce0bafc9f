"""Check a robot description before an experiment: it loads (joints, limits, TCP, camera
mount), the joint table, the TCP clear of the palm, the camera looking at the table (its first
image saved), a reachability map of the scene, and a few autonomous grasps in lock-step; plain
lines say what to fix.

    mindgrasp robot check config/robots/xarm6.yaml
    mindgrasp robot check my_robot.yaml --grasps 6 --out runs/check_my_robot
    mindgrasp robot check kuka_iiwa+mindgrasp_hand --grasps 0
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp robot check``."""
    from mindgrasp_common.cli_checks import non_negative_int

    parser.add_argument('robot', metavar='NAME|YAML|ARM+HAND',
                        help='a robot description YAML file, a shipped robot name, or a pair '
                             'ARM+HAND of shipped arm and hand names')
    parser.add_argument('--out', metavar='DIR', default=None,
                        help='where camera.png, reachability.png/.csv and the grasp run go '
                             '(default runs/robot_check_<name>/)')
    parser.add_argument('--grasps', type=non_negative_int, default=6, metavar='N',
                        help='autonomous random-locations grasps in lock-step (default 6, about '
                             'two of each shape; 0: none)')
    parser.add_argument('--seed', type=non_negative_int, default=0,
                        help='seed of the grasp trials (default 0)')
    parser.add_argument('--realism', default='default',
                        help="the grasps' realism profile: default (default), none or a YAML path")


def _say(finding) -> None:
    print(f"{'ok ' if finding.ok else 'FIX'} {finding.line}")


def main(args: argparse.Namespace) -> int:
    """Exit 0 when every check passes, 1 when one names a fault, 2 for bad arguments."""
    from mindgrasp_common.robot_description import RobotDescriptionError, load_robot
    from mindgrasp_experiments.robot_check import (
        Finding,
        camera_findings,
        joint_table,
        reachability,
        tcp_findings,
    )

    try:
        robot = load_robot(args.robot)
    except RobotDescriptionError as exc:
        _say(Finding(False, str(exc)))
        return 1
    print(f'Robot {robot.name!r}: arm '
          f"{robot.arm.name if robot.arm else '(single URDF)'}, hand "
          f"{robot.hand.name if robot.hand else '(single URDF)'}, {len(robot.arm_joints)} arm "
          f'joints, {len(robot.gripper.joints)} hand joints ({robot.gripper.kind}, grasp check '
          f'{robot.gripper.grasp_check}); URDF {robot.urdf}')
    for line in joint_table(robot):
        print('    ' + line)
    out = Path(args.out) if args.out else \
        Path('runs') / f"robot_check_{robot.name.replace('+', '_')}"
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f'mindgrasp robot check: cannot create --out {str(out)!r} ({exc.strerror}); give a '
              'writable folder.', file=sys.stderr)
        return 2
    from mindgrasp_sim.errors import SimError
    from mindgrasp_sim.simulation import Simulation

    try:
        sim = Simulation('set_locations', seed=0, robot=robot)
    except SimError as exc:
        _say(Finding(False, str(exc)))
        return 1
    try:
        findings = [*tcp_findings(sim), *camera_findings(sim, out)]
    finally:
        sim.close()
    for f in findings:
        _say(f)
    print(f'    first camera image: {out / "camera.png"}')
    if not all(f.ok for f in findings):
        print(f'{robot.name}: {sum(not f.ok for f in findings)} check(s) to fix (FIX lines '
              'above); the reachability map and the grasps wait until they pass')
        return 1
    reach, _ = reachability(robot, out)
    findings.append(Finding(reach >= 0.5, f'grasp poses for {reach * 100:.0f} % of the object '
                                          'positions 0.2-0.7 m from the base' + (
                                              '' if reach >= 0.5 else
                                              '; check the home pose, the joint limits and the '
                                              'TCP')))
    _say(findings[-1])
    print(f'    reachability map: {out / "reachability.png"}')
    if args.grasps and all(f.ok for f in findings):
        from mindgrasp_experiments import ExperimentError
        from mindgrasp_experiments.experiment import Experiment

        experiment = Experiment('random_locations', subject='autonomous', trials=args.grasps,
                                seed=args.seed, robot=robot.spec, realism=args.realism,
                                trial_timeout_s=300.0)
        try:
            results = experiment.run(out / 'grasps', command=' '.join(sys.argv),
                                     log=lambda _line: None)
        except ExperimentError as exc:
            _say(Finding(False, f'the grasp run did not start: {exc}'))
            return 1
        done = Counter(r.desired.split()[-1] for r in results.records if r.desired)
        held = Counter(r.desired.split()[-1] for r in results.records
                       if r.desired and r.correct_and_successful)
        per = ', '.join(f'{s} {held[s]}/{done[s]}' for s in sorted(done))
        ok = sum(held.values()) == len(results.records) and results.records
        findings.append(Finding(bool(ok), f'autonomous grasps (random locations, seed '
                                          f'{args.seed}, realism {args.realism}): {per}' + (
                                              '' if ok else f'; see {results.run_dir / "report.md"}'
                                              ' for each failure')))
        _say(findings[-1])
        info = results.info
        print(f"    lock-step real-time factor {info['real_time_factor']:.1f}, "
              f"{info['cpu_s_per_sim_s']:.3f} CPU s per simulated s")
    faults = sum(not f.ok for f in findings)
    print(f'{robot.name}: ' + ('every check passed' if not faults else
                               f'{faults} check(s) to fix (FIX lines above)'))
    return 1 if faults else 0
