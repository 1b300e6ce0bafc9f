"""The grasp experiments of the paper: the trial manager runs set-locations or random-locations
trials through the full node graph (simulator, EEG, classifier, vision, controller).

    mindgrasp launch experiment subject:=virtual accuracy:=0.8 trials:=6 --lockstep
    mindgrasp launch experiment protocol:=random_locations subject:=autonomous trials:=3
    mindgrasp experiment set-locations --trials 160 --subject noise     # records and report
    mindgrasp experiment random-locations --subject autonomous --robot xarm6 --trials 1

Subjects: ``noise`` (the paper's unworn cap: EEG without imagery, decoded by a classifier trained
on noise; give it with model:=), ``virtual`` (the virtual subject pursues the target at
``accuracy``; the default classifier was calibrated on the same simulated subject with another
seed), ``oracle`` (no EEG: the subject's intended class is published as the prediction) and
``autonomous`` (no BCI: the controller searches and grasps by itself, as in random locations).
With ``--lockstep`` every node runs in one process on simulated time; the virtual amplifier then
publishes /eeg/raw itself and the LSL acquisition node is left out.

Parameters: config/param/<package>.yaml, then config/profiles/experiment.yaml, then the launch
arguments below.
"""

from mindgrasp_eeg.subject_file import check_eeg_source
from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    EqualsSubstitution,
    GroupAction,
    IfCondition,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    NotEqualsSubstitution,
    Shutdown,
    checked_argument,
    command_interface_argument,
    config_files,
    file_argument,
    fsm_node,
    number_argument,
    robot_argument,
    run_directory_actions,
    virtual_amp_pin,
)


def _when(subject: str) -> IfCondition:
    return IfCondition(EqualsSubstitution(LaunchConfiguration('subject'), subject))


def generate_launch_description() -> LaunchDescription:
    seed = LaunchConfiguration('seed')
    subject = LaunchConfiguration('subject')
    stream = LaunchConfiguration('eeg_stream')
    model = LaunchConfiguration('model')
    manager = [*config_files('experiment'),
               {'protocol': LaunchConfiguration('protocol'), 'n_trials': LaunchConfiguration(
                   'trials'), 'first_trial': LaunchConfiguration('first_trial'), 'seed': seed,
                'subject': subject}]
    waits = {'noise': ['/eeg/raw', '/bci/prediction', '/vision/detections'],
             'virtual': ['/eeg/raw', '/bci/prediction', '/vision/detections'],
             'oracle': ['/bci/prediction', '/vision/detections'],
             'autonomous': ['/vision/detections']}
    eeg = config_files('eeg', 'experiment')
    amp_pin, acquisition_pin = virtual_amp_pin()   # this run's amplifier only (live runs)
    classifier = config_files('classifier', 'experiment')
    return LaunchDescription([
        DeclareLaunchArgument('protocol', default_value='set_locations',
                              choices=['set_locations', 'random_locations'],
                              description='set_locations (9 objects at 0.5 m, a desired object '
                                          'per trial) or random_locations (one object per '
                                          'trial at 0.2-0.7 m)'),
        DeclareLaunchArgument('subject', default_value='virtual',
                              choices=['noise', 'virtual', 'oracle', 'autonomous'],
                              description='who drives the controller (see the profile help)'),
        number_argument('accuracy', default_value='0.8', kind=float, minimum=0, maximum=1,
                        description='virtual subject: probability (0-1) that a decision '
                                    'is the right class'),
        checked_argument('eeg_source', check=check_eeg_source, default_value='synthetic',
                         description='EEG of the virtual subject: synthetic (head model), '
                                     'eegmmidb:<subject> or path/to/subject.yaml (a replay '
                                     'subject: real imagery epochs of the intended class; '
                                     'give the calibrated model:=)'),
        number_argument('trials', default_value='3', minimum=0,
                        description='trials before the launch ends (0: until Ctrl-C)'),
        number_argument('first_trial', default_value='1', minimum=1,
                        description='number of the first trial (trials are drawn from '
                                    '(seed, trial), so a batch can start anywhere)'),
        number_argument('seed', default_value='0', minimum=0,
                        description='seed of the protocol draws, the EEG and the subject'),
        file_argument('model', default_value='',
                      description='classifier model (.json); empty: the default model '
                                  '(the noise subject needs a noise-trained one)'),
        DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-Experiment',
                              description='LSL stream name of the virtual amplifier (live runs)'),
        DeclareLaunchArgument('realism', default_value='none',
                              description='simulator realism: none, default or a profile YAML '
                                          '(sensor noise, camera mount error, arm lag, object '
                                          'spread; mindgrasp_sim.realism), seeded by seed'),
        robot_argument(),
        DeclareLaunchArgument('gui', default_value='false', choices=['true', 'false'],
                              description='open the PyBullet window (needs a display)'),
        command_interface_argument(),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        *[Node(package='mindgrasp_experiments', executable='trial_manager_node',
               name='trial_manager', parameters=[*manager, {'wait_for': topics}],
               condition=_when(name), on_exit=Shutdown(reason='the trials are done'))
          for name, topics in waits.items()],
        Node(package='mindgrasp_sim', executable='sim_node', name='sim',
             parameters=[*config_files('sim', 'experiment'),
                         {'gui': LaunchConfiguration('gui'), 'seed': seed,
                          'realism': LaunchConfiguration('realism'), 'realism_seed': seed,
                          'scene': LaunchConfiguration('protocol'),  # a scene per protocol
                          'robot': LaunchConfiguration('robot')}]),
        # EEG subjects: the virtual amplifier (pursue: the virtual subject; noise: the unworn
        # cap), acquisition and the classifier
        *[GroupAction([
            Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
                 parameters=[*eeg, {'stream_name': stream, **amp_pin, 'seed': seed,
                                    'accuracy': LaunchConfiguration('accuracy'),
                                    'eeg_source': LaunchConfiguration('eeg_source'),
                                    'subject_mode': mode,
                                    'robot': LaunchConfiguration('robot')}]),
            Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
                 parameters=[*eeg, {'stream_name': stream, **acquisition_pin}]),
            Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                 parameters=classifier, condition=IfCondition(EqualsSubstitution(model, ''))),
            Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                 parameters=[*classifier, {'model': model}],
                 condition=IfCondition(NotEqualsSubstitution(model, ''))),
        ], condition=_when(name)) for name, mode in (('noise', 'noise'), ('virtual', 'pursue'))],
        Node(package='mindgrasp_experiments', executable='oracle_subject_node',
             name='oracle_subject',
             parameters=[{'seed': seed, 'robot': LaunchConfiguration('robot')}],
             condition=_when('oracle')),
        Node(package='mindgrasp_vision', executable='vision_node', name='vision',
             parameters=config_files('vision', 'experiment')),
        fsm_node(config_files('fsm', 'experiment'),
                 {'autonomous': EqualsSubstitution(subject, 'autonomous'),
                  'robot': LaunchConfiguration('robot'),
                  # the person's answer pair and decision thresholds (fsm answer_pair: auto)
                  'classifier_model': model}),
    ])

