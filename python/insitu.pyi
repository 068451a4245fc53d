# Type hints of the compiled module insitu (python/src/*.cpp; docstrings there, help(insitu)).
import enum
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy
import numpy.typing as npt

class Error(RuntimeError): ...
class InvalidArgument(Error, ValueError): ...
class ParseError(Error, ValueError): ...
class ComputeError(Error): ...
class IoError(Error, OSError): ...
class StateError(Error): ...
class InvariantError(Error): ...

_Path = Union[str, os.PathLike[str]]
_Triple = Tuple[float, float, float]
_Ghosts = Union[int, Tuple[int, int, int], Tuple[Tuple[int, int, int], Tuple[int, int, int]]]
_Light = Union[str, Tuple[float, float], Tuple[float, float, float],
               Tuple[float, float, float, float]]

class Proxies:
    step: int
    view: int
    multi_perspective: bool
    isovalues: List[float]
    intervals: Optional[List[float]]
    camera: Dict[str, Any]
    def keys(self) -> List[str]: ...
    def __contains__(self, name: str) -> bool: ...
    def __getitem__(self, name: str) -> npt.NDArray[numpy.float32]: ...
    def channels(self, name: str) -> List[str]: ...

class LightField:
    cameras: List[int]
    rig: Dict[str, Any]
    settings: Dict[str, Any]
    transfer_function: Dict[str, Any]
    isovalues: List[float]
    intervals: Optional[List[float]]
    segment_count: int
    def camera(self, index: int) -> Dict[str, npt.NDArray[numpy.float32]]: ...

class Frame:
    rgba: npt.NDArray[numpy.float32]
    confidence: npt.NDArray[numpy.float32]
    camera: Dict[str, Any]
    synthesised_view: bool
    colour_source: str
    proxy_source: str
    opacity_scales: List[float]
    light_field_share: float
    missing_cameras: List[int]
    milliseconds: float
    note: str
    def srgb8(self) -> npt.NDArray[numpy.uint8]: ...

class Archive:
    path: str
    steps: List[int]
    times: List[float]
    fields: List[str]
    views: List[Dict[str, Any]]
    manifest: Dict[str, Any]
    diagnostics: List[str]
    def damage(self) -> List[str]: ...
    def refresh(self) -> None: ...
    def transfer_function(self, step: int, view: int = 0) -> Dict[str, Any]: ...
    def proxies(self, step: int, view: int = 0, multi: bool = False) -> Proxies: ...
    def preview(self, step: int, view: int = 0) -> npt.NDArray[numpy.float32]: ...
    def light_fields(self, step: int) -> List[Dict[str, Any]]: ...
    def light_field(self, step: int, field: str, cameras: Sequence[int] = ...) -> LightField: ...
    def volumes(self, step: int) -> List[Dict[str, Any]]: ...
    def volume(self, step: int, field: str = "") -> npt.NDArray[numpy.float32]: ...
    def render(self, step: int, *, view: int = 0, azimuth: Optional[float] = None,
               elevation: Optional[float] = None,
               tf: Optional[Union[Dict[str, Any], _Path]] = None,
               opacity_scale: Optional[Union[Mapping[int, float],
                                             Sequence[Tuple[int, float]]]] = None,
               segment_opacity: Optional[Union[Mapping[int, float],
                                               Sequence[Tuple[int, float]]]] = None,
               colours: Optional[str] = None, source: Optional[str] = None,
               lights: Optional[Sequence[_Light]] = None, ambient: Optional[float] = None,
               ao: Optional[Union[bool, int, Tuple[int, float]]] = None,
               enhance: Optional[Tuple[float, float]] = None,
               fill: Optional[int] = None) -> Frame: ...
    def export_cinema(self, directory: _Path, *, steps: Optional[Sequence[int]] = None,
                      views: Optional[Sequence[int]] = None,
                      tfs: Optional[Sequence[Union[Dict[str, Any], _Path]]] = None,
                      azimuths: Optional[Sequence[float]] = None,
                      elevations: Optional[Sequence[float]] = None) -> int: ...

def open(path: _Path, damaged: bool = False) -> Archive: ...
def to_srgb8(linear: npt.ArrayLike) -> npt.NDArray[numpy.uint8]: ...
def read_exr(path: str, channels: Sequence[str] = ...) -> npt.NDArray[numpy.float32]: ...

class Status(enum.Enum):
    ok = 0
    not_selected = 1
    dropped = 2
    error = 3

class Field:
    data: numpy.ndarray
    def __init__(self, data: numpy.ndarray, *, ghost_layers: Optional[_Ghosts] = None,
                 spacing: Optional[_Triple] = None, origin: Optional[_Triple] = None,
                 centering: Optional[str] = None) -> None: ...

_FieldValue = Union[numpy.ndarray, Field, Sequence[Union[numpy.ndarray, Field]]]

class Instrument:
    statistics: Dict[str, Union[int, float]]
    last_error: str
    first_error: str
    config: Dict[str, Any]
    def __init__(self, config: Union[Dict[str, Any], _Path], *, raise_errors: bool = False,
                 log: bool = True, comm: Optional[Any] = None) -> None: ...
    def execute(self, step: int, time: float, fields: Mapping[str, _FieldValue], *,
                ghost_layers: Optional[_Ghosts] = None, spacing: Optional[_Triple] = None,
                origin: Optional[_Triple] = None, centering: Optional[str] = None) -> Status: ...
    def selects(self, step: int) -> bool: ...
    def finalize(self) -> Status: ...
    def __enter__(self) -> "Instrument": ...
    def __exit__(self, *args: Any) -> None: ...
