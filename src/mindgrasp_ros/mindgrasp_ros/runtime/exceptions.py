"""``rclpy.exceptions`` equivalents."""

from mindgrasp_ros.errors import RosError

__all__ = [
    'InvalidNameError', 'InvalidParameterTypeException', 'InvalidParameterValueException',
    'NotInitializedException', 'ParameterAlreadyDeclaredException', 'ParameterException',
    'ParameterNotDeclaredException', 'ParameterUninitializedException', 'RCLError',
    'ROSInterruptException',
]


class RCLError(RosError):
    """Generic error of the client library."""


class NotInitializedException(RCLError):
    def __init__(self, what: str = 'context') -> None:
        super().__init__(f'The {what} is not initialized: call rclpy.init() first.')


class InvalidNameError(RCLError, ValueError):
    """An invalid node, namespace, topic or service name."""


class ROSInterruptException(RCLError):
    """The context was shut down while waiting."""


class ParameterException(RCLError):
    """Base class of parameter errors."""

    def __init__(self, error_msg: str, parameters: object = None) -> None:
        super().__init__(error_msg if parameters is None else f'{error_msg}: {parameters}')


class ParameterNotDeclaredException(ParameterException):
    def __init__(self, parameters: object) -> None:
        RCLError.__init__(self, f"Parameter '{parameters}' has not been declared: declare it "
                                'with declare_parameter() before using it, or construct the node '
                                'with allow_undeclared_parameters=True.')


class ParameterAlreadyDeclaredException(ParameterException):
    def __init__(self, parameters: object) -> None:
        RCLError.__init__(self, f"Parameter '{parameters}' has already been declared.")


class ParameterUninitializedException(ParameterException):
    def __init__(self, parameter_name: str) -> None:
        RCLError.__init__(self, f"Parameter '{parameter_name}' has no value: give it one with "
                                f'-p {parameter_name}:=VALUE or in a params file.')


class InvalidParameterTypeException(ParameterException):
    def __init__(self, parameter: object, expected_type: object) -> None:
        RCLError.__init__(self, f"Trying to set parameter '{getattr(parameter, 'name', parameter)}'"
                                f' to {getattr(parameter, "value", "?")!r} of type '
                                f'{getattr(getattr(parameter, "type_", None), "name", "?")}, '
                                f'expecting type {getattr(expected_type, "name", expected_type)}.')


class InvalidParameterValueException(ParameterException):
    def __init__(self, parameter: str, value: object, reason: str) -> None:
        RCLError.__init__(self, f"Invalid value {value!r} for parameter '{parameter}': {reason}")
