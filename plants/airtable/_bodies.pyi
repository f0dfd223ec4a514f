"""Types of the air table's compiled body input/output (plants/airtable/_bodies.c documents
each)."""

from typing import Any, Callable

Buffer = Any  # ptrs: array('Q') of 10 addresses; state: array('d') of 10; hand: array('d') of 26

def read(ptrs: Buffer, state: Buffer) -> None: ...
def step(
    ptrs: Buffer,
    state: Buffer,
    tx0: float,
    ty0: float,
    tx1: float,
    ty1: float,
    dt: float,
    space_step: Callable[[float], None] | None,
    rest_speed: float,
    rest_omega: float,
    hold_speed: float,
    hold_omega: float,
) -> bool: ...
def step_hand(
    ptrs: Buffer,
    state: Buffer,
    hand: Buffer,
    dt: float,
    space_step: Callable[[float], None] | None,
    rest_speed: float,
    rest_omega: float,
    hold_speed: float,
    hold_omega: float,
) -> bool: ...
