from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Vector3(_message.Message):
    __slots__ = ("X", "Y", "Z")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    X: float
    Y: float
    Z: float
    def __init__(self, X: _Optional[float] = ..., Y: _Optional[float] = ..., Z: _Optional[float] = ...) -> None: ...

class PositionSensorMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: float
    def __init__(self, name: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...

class AccelerometerMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: Vector3
    def __init__(self, name: _Optional[str] = ..., value: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class BumperMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: bool
    def __init__(self, name: _Optional[str] = ..., value: _Optional[bool] = ...) -> None: ...

class CameraMeasurement(_message.Message):
    __slots__ = ("name", "width", "height", "quality", "image")
    NAME_FIELD_NUMBER: _ClassVar[int]
    WIDTH_FIELD_NUMBER: _ClassVar[int]
    HEIGHT_FIELD_NUMBER: _ClassVar[int]
    QUALITY_FIELD_NUMBER: _ClassVar[int]
    IMAGE_FIELD_NUMBER: _ClassVar[int]
    name: str
    width: int
    height: int
    quality: int
    image: bytes
    def __init__(self, name: _Optional[str] = ..., width: _Optional[int] = ..., height: _Optional[int] = ..., quality: _Optional[int] = ..., image: _Optional[bytes] = ...) -> None: ...

class ForceMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: float
    def __init__(self, name: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...

class Force3DMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: Vector3
    def __init__(self, name: _Optional[str] = ..., value: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class Force6DMeasurement(_message.Message):
    __slots__ = ("name", "force", "torque")
    NAME_FIELD_NUMBER: _ClassVar[int]
    FORCE_FIELD_NUMBER: _ClassVar[int]
    TORQUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    force: Vector3
    torque: Vector3
    def __init__(self, name: _Optional[str] = ..., force: _Optional[_Union[Vector3, _Mapping]] = ..., torque: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class GyroMeasurement(_message.Message):
    __slots__ = ("name", "value")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    value: Vector3
    def __init__(self, name: _Optional[str] = ..., value: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class Message(_message.Message):
    __slots__ = ("message_type", "text")
    class MessageType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        ERROR_MESSAGE: _ClassVar[Message.MessageType]
        WARNING_MESSAGE: _ClassVar[Message.MessageType]
    ERROR_MESSAGE: Message.MessageType
    WARNING_MESSAGE: Message.MessageType
    MESSAGE_TYPE_FIELD_NUMBER: _ClassVar[int]
    TEXT_FIELD_NUMBER: _ClassVar[int]
    message_type: Message.MessageType
    text: str
    def __init__(self, message_type: _Optional[_Union[Message.MessageType, str]] = ..., text: _Optional[str] = ...) -> None: ...

class SensorMeasurements(_message.Message):
    __slots__ = ("time", "real_time", "messages", "accelerometers", "bumpers", "cameras", "forces", "force3ds", "force6ds", "gyros", "position_sensors")
    TIME_FIELD_NUMBER: _ClassVar[int]
    REAL_TIME_FIELD_NUMBER: _ClassVar[int]
    MESSAGES_FIELD_NUMBER: _ClassVar[int]
    ACCELEROMETERS_FIELD_NUMBER: _ClassVar[int]
    BUMPERS_FIELD_NUMBER: _ClassVar[int]
    CAMERAS_FIELD_NUMBER: _ClassVar[int]
    FORCES_FIELD_NUMBER: _ClassVar[int]
    FORCE3DS_FIELD_NUMBER: _ClassVar[int]
    FORCE6DS_FIELD_NUMBER: _ClassVar[int]
    GYROS_FIELD_NUMBER: _ClassVar[int]
    POSITION_SENSORS_FIELD_NUMBER: _ClassVar[int]
    time: int
    real_time: int
    messages: _containers.RepeatedCompositeFieldContainer[Message]
    accelerometers: _containers.RepeatedCompositeFieldContainer[AccelerometerMeasurement]
    bumpers: _containers.RepeatedCompositeFieldContainer[BumperMeasurement]
    cameras: _containers.RepeatedCompositeFieldContainer[CameraMeasurement]
    forces: _containers.RepeatedCompositeFieldContainer[ForceMeasurement]
    force3ds: _containers.RepeatedCompositeFieldContainer[Force3DMeasurement]
    force6ds: _containers.RepeatedCompositeFieldContainer[Force6DMeasurement]
    gyros: _containers.RepeatedCompositeFieldContainer[GyroMeasurement]
    position_sensors: _containers.RepeatedCompositeFieldContainer[PositionSensorMeasurement]
    def __init__(self, time: _Optional[int] = ..., real_time: _Optional[int] = ..., messages: _Optional[_Iterable[_Union[Message, _Mapping]]] = ..., accelerometers: _Optional[_Iterable[_Union[AccelerometerMeasurement, _Mapping]]] = ..., bumpers: _Optional[_Iterable[_Union[BumperMeasurement, _Mapping]]] = ..., cameras: _Optional[_Iterable[_Union[CameraMeasurement, _Mapping]]] = ..., forces: _Optional[_Iterable[_Union[ForceMeasurement, _Mapping]]] = ..., force3ds: _Optional[_Iterable[_Union[Force3DMeasurement, _Mapping]]] = ..., force6ds: _Optional[_Iterable[_Union[Force6DMeasurement, _Mapping]]] = ..., gyros: _Optional[_Iterable[_Union[GyroMeasurement, _Mapping]]] = ..., position_sensors: _Optional[_Iterable[_Union[PositionSensorMeasurement, _Mapping]]] = ...) -> None: ...

class MotorPosition(_message.Message):
    __slots__ = ("name", "position")
    NAME_FIELD_NUMBER: _ClassVar[int]
    POSITION_FIELD_NUMBER: _ClassVar[int]
    name: str
    position: float
    def __init__(self, name: _Optional[str] = ..., position: _Optional[float] = ...) -> None: ...

class MotorVelocity(_message.Message):
    __slots__ = ("name", "velocity")
    NAME_FIELD_NUMBER: _ClassVar[int]
    VELOCITY_FIELD_NUMBER: _ClassVar[int]
    name: str
    velocity: float
    def __init__(self, name: _Optional[str] = ..., velocity: _Optional[float] = ...) -> None: ...

class MotorForce(_message.Message):
    __slots__ = ("name", "force")
    NAME_FIELD_NUMBER: _ClassVar[int]
    FORCE_FIELD_NUMBER: _ClassVar[int]
    name: str
    force: float
    def __init__(self, name: _Optional[str] = ..., force: _Optional[float] = ...) -> None: ...

class MotorTorque(_message.Message):
    __slots__ = ("name", "torque")
    NAME_FIELD_NUMBER: _ClassVar[int]
    TORQUE_FIELD_NUMBER: _ClassVar[int]
    name: str
    torque: float
    def __init__(self, name: _Optional[str] = ..., torque: _Optional[float] = ...) -> None: ...

class MotorPID(_message.Message):
    __slots__ = ("name", "PID")
    NAME_FIELD_NUMBER: _ClassVar[int]
    PID_FIELD_NUMBER: _ClassVar[int]
    name: str
    PID: Vector3
    def __init__(self, name: _Optional[str] = ..., PID: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class SensorTimeStep(_message.Message):
    __slots__ = ("name", "timeStep")
    NAME_FIELD_NUMBER: _ClassVar[int]
    TIMESTEP_FIELD_NUMBER: _ClassVar[int]
    name: str
    timeStep: int
    def __init__(self, name: _Optional[str] = ..., timeStep: _Optional[int] = ...) -> None: ...

class CameraQuality(_message.Message):
    __slots__ = ("name", "quality")
    NAME_FIELD_NUMBER: _ClassVar[int]
    QUALITY_FIELD_NUMBER: _ClassVar[int]
    name: str
    quality: int
    def __init__(self, name: _Optional[str] = ..., quality: _Optional[int] = ...) -> None: ...

class CameraExposure(_message.Message):
    __slots__ = ("name", "exposure")
    NAME_FIELD_NUMBER: _ClassVar[int]
    EXPOSURE_FIELD_NUMBER: _ClassVar[int]
    name: str
    exposure: float
    def __init__(self, name: _Optional[str] = ..., exposure: _Optional[float] = ...) -> None: ...

class ActuatorRequests(_message.Message):
    __slots__ = ("motor_positions", "motor_velocities", "motor_forces", "motor_torques", "motor_pids", "sensor_time_steps", "camera_qualities", "camera_exposures")
    MOTOR_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    MOTOR_VELOCITIES_FIELD_NUMBER: _ClassVar[int]
    MOTOR_FORCES_FIELD_NUMBER: _ClassVar[int]
    MOTOR_TORQUES_FIELD_NUMBER: _ClassVar[int]
    MOTOR_PIDS_FIELD_NUMBER: _ClassVar[int]
    SENSOR_TIME_STEPS_FIELD_NUMBER: _ClassVar[int]
    CAMERA_QUALITIES_FIELD_NUMBER: _ClassVar[int]
    CAMERA_EXPOSURES_FIELD_NUMBER: _ClassVar[int]
    motor_positions: _containers.RepeatedCompositeFieldContainer[MotorPosition]
    motor_velocities: _containers.RepeatedCompositeFieldContainer[MotorVelocity]
    motor_forces: _containers.RepeatedCompositeFieldContainer[MotorForce]
    motor_torques: _containers.RepeatedCompositeFieldContainer[MotorTorque]
    motor_pids: _containers.RepeatedCompositeFieldContainer[MotorPID]
    sensor_time_steps: _containers.RepeatedCompositeFieldContainer[SensorTimeStep]
    camera_qualities: _containers.RepeatedCompositeFieldContainer[CameraQuality]
    camera_exposures: _containers.RepeatedCompositeFieldContainer[CameraExposure]
    def __init__(self, motor_positions: _Optional[_Iterable[_Union[MotorPosition, _Mapping]]] = ..., motor_velocities: _Optional[_Iterable[_Union[MotorVelocity, _Mapping]]] = ..., motor_forces: _Optional[_Iterable[_Union[MotorForce, _Mapping]]] = ..., motor_torques: _Optional[_Iterable[_Union[MotorTorque, _Mapping]]] = ..., motor_pids: _Optional[_Iterable[_Union[MotorPID, _Mapping]]] = ..., sensor_time_steps: _Optional[_Iterable[_Union[SensorTimeStep, _Mapping]]] = ..., camera_qualities: _Optional[_Iterable[_Union[CameraQuality, _Mapping]]] = ..., camera_exposures: _Optional[_Iterable[_Union[CameraExposure, _Mapping]]] = ...) -> None: ...
