"""Control loops designed and checked with python-control (named so it never shadows ``control``).

Layer: below the system lessons (``outdoor``, ``legged``); imports only ``geometry``,
``validation`` and python-control.

heading       the heading servo of a skid-steer vehicle: pole-placement gains for an overshoot and
              settling time, and the discrete controller (lesson 05; re-exported by
              :mod:`robokit.outdoor`)
heading_loop  that loop as transfer functions: plant, closed loop, loop gain, step and frequency
              response, margins (no exercise reference: graded notebooks may import it)
"""
from .heading import HeadingController, design_heading_gains
from .heading_loop import (heading_closed_loop, heading_frequency_response, heading_loop_gain, heading_plant,
                           heading_step_response, loop_metrics)

__all__ = ["HeadingController", "design_heading_gains", "heading_closed_loop", "heading_frequency_response",
           "heading_loop_gain", "heading_plant", "heading_step_response", "loop_metrics"]
