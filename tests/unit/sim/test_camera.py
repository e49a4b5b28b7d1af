"""The simulated camera's test pattern moves, is labelled, and keeps its colour bars."""

import numpy as np

from rover_web.sim.camera import BARS, PatternFrames, pattern_image


def test_pattern_has_the_colour_bars():
    image = pattern_image(640, 480)
    assert image.shape == (480, 640, 3) and image.dtype == np.uint8
    for i, colour in enumerate(BARS):
        x = i * 80 + 40
        assert tuple(image[200, x]) == colour


def test_frames_move_and_carry_a_label():
    frames = PatternFrames(640, 480, speed_px=4)
    first, second = frames.frame(0, 1000.0), frames.frame(1, 1000.0)
    assert first.shape == (480, 640, 3)
    # Below the label, frame 1 is frame 0 shifted left by 4 pixels.
    assert np.array_equal(second[200, :-4], first[200, 4:])
    assert not np.array_equal(first, second)
    # The label box is black with white text, different for another frame number.
    box = first[10:40, 10:200]
    assert (box == 0).mean() > 0.5 and box.max() == 255
    assert not np.array_equal(frames.frame(7, 1000.0)[10:40, 10:200], box)


def test_grain_is_fixed_so_it_moves_with_the_pattern():
    clean, grainy = PatternFrames(64, 48), PatternFrames(64, 48, speed_px=4, noise=12.0)
    a, b = grainy.frame(0, 0.0), grainy.frame(1, 0.0)
    assert np.abs(a.astype(int) - clean.frame(0, 0.0)).mean() > 3  # grain is there
    assert np.array_equal(b[40, :-4], a[40, 4:])  # and scrolls with the pattern, costing nothing per frame
