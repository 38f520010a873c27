"""Chapter 3's claims (the minimum variance model's trajectories, Figs. 3.2-3.9), as data.

Measured by :mod:`tools.thesis.ch3_reach`, :mod:`tools.thesis.ch3_letters` and
:mod:`tools.thesis.ch3_iteration`; checked by :func:`tools.thesis.claims.evaluate`.
"""

from tools.thesis.ch3_tasks import HUMAN_LIKE
from tools.thesis.claims import Claim, above, below, equals, holds

CLAIMS = (
    Claim(
        "same-answer", "3.2.2.2",
        "The filter/controller iteration converges to the same answer whatever it starts from",
        "always converges, to the same answer regardless of initialisation",
        "line 481 (citing Todorov & Jordan); line 483",
        "the 's' of Fig. 3.6 solved from first-pass control laws: zero (the thesis's); the "
        "optimum x 2; the optimum x 5; the optimum of an 's' with other via-points; random "
        "gains at 0.1 of the optimum's size; random gains at 0.3 of the optimum's size; the "
        "optimum x -1. Agree if every start whose first pass stays finite reaches the zero "
        "start's cost and gains within 1e-6 (relative)",
        rule=(below("largest_relative_difference", 1e-6),),
        line=481,
        quote="to the same answer regardless of initialisation",
    ),
    Claim(
        "exponential", "3.2.2.2",
        "The filter/controller iteration converges exponentially",
        "converges exponentially",
        "3.2.2.2; line 481",
        "the 's' of Fig. 3.6 from the zero start: the cost's distance from its final value, "
        "iteration by iteration; agree if it shrinks by a factor below 1 at every iteration (at"
        " least geometrically)",
        rule=(holds("shrinks_every_iteration"),),
        line=481,
        quote="iteration always converges exponentially",
    ),
    Claim(
        "noise-blind", "3.1",
        "A law that ignores the noise gives the same trajectories at any noise level; the "
        "minimum variance law does not",
        "the same trajectories regardless of the relative level of that noise (noise-blind "
        "laws)",
        "3.1; line 388",
        "expected (noise-averaged) path of the 's' planned at two noise levels; agree if the "
        "minimum variance plan changes (beyond rounding) while a fixed law's mean path cannot",
        rule=(above("plan_change_m", 1e-6),),
        line=388,
        quote="will produce the same trajectories regardless of the relative level of that noise",
    ),
    Claim(
        "post-movement", "3.2.2.3",
        "A post-movement period does not change the trajectories",
        "does not fundamentally change ... the trajectories it produces",
        "3.2.2.3; line 545",
        "Fig. 3.4's reach planned with the goal as a via-point at 500 ms and 200 ms at rest "
        "after it, against the plain reach: Hausdorff distance of the expected paths over the "
        "movement; agree if below the repetition noise",
        rule=(below("apart_m", "scatter_m"),),
        line=545,
        quote="does not fundamentally change the principle of the implementation, or the "
              "trajectories"
        " it produces",
    ),
    Claim(
        "viapoint-time-shape", "3.2.3",
        "A via-point's time changes the trajectory's shape (25 % vs 75 %)",
        "significant impact",
        "Fig. 3.2(a); lines 583, 587",
        "Hausdorff distance between the expected paths with the via-point at 25 % and at 75 %; "
        "agree above 10 % of the movement length",
        rule=(above("apart_m", 0.03),),
        line=587,
        quote="has a significant impact on the shape of the resulting trajectory",
    ),
    Claim(
        "viapoint-shift-100ms", "3.2.3",
        "Via-point time differences up to about 100 ms barely change the trajectory",
        "do not significantly alter the trajectory (MSD, Fig. 3.2(b))",
        "Fig. 3.2(b); lines 583, 591",
        "eq. A.2 MSD (joint space, the figure's quantity) of the expected path with the "
        "via-point shifted by ±100 ms against the unshifted one; 'significantly' judged against"
        " the repetition noise: agree if it is below the mean MSD between a noisy repetition "
        "(50) and the expected path",
        rule=(below("msd_100ms", "repetition_msd"),),
        line=591,
        quote="up to about 100ms do not significantly alter the trajectory",
    ),
    Claim(
        "merging", "3.2.3",
        "A target turned into a via-point merges two movements",
        "A->C via B shows both movements' contributions",
        "Fig. 3.3; lines 606-610",
        "mean path of the repetitions: agree if it passes within 5 mm of B with one speed peak "
        "per merged movement",
        rule=(below("closest_to_b_m", 0.005), equals("speed_peaks", 2)),
        line=606,
        quote="Movement 3 between points A and C has a via-point at B",
    ),
    Claim(
        "reach-bell", "3.3.1",
        "Point-to-point speed profile: a single bell",
        "bell-shaped",
        "Fig. 3.4(b,d); line 634",
        "speed peaks (prominence 5 % of the maximum) of the mean profile; agree if one",
        rule=(equals("speed_peaks", 1),),
        line=634,
        quote="follow the characteristic bell-shape",
    ),
    Claim(
        "human-like", "3.3.1",
        "The speed profile is human-like: its peak/mean ratio",
        "not given for Fig. 3.4(d); humans r = 1.875 (line 276, Fig. 2.6(c))",
        "line 622 (the model 'exhibited the required features of human movement'); the human "
        "ratio from line 276",
        "peak/mean of the mean speed profile; agree if nearer the human 1.875 than the ratios "
        "of the neighbouring derivative orders of Fig. 2.6(c) (1.5 for n = 2, 2.19 for n = 4): "
        "1.69-2.03",
        rule=(above("peak_to_mean", HUMAN_LIKE[0]), below("peak_to_mean", HUMAN_LIKE[1])),
        line=622,
        quote="exhibited the required features of human movement",
    ),
    Claim(
        "mean-straight", "3.3.1",
        "The mean path is a straight line",
        "straight",
        "Fig. 3.4(c); lines 622, 636",
        "largest distance of the mean path from the start-goal line (within 1 % of the reach "
        "length, the mean's sampling error included)",
        rule=(below("mean_deviation_m", 0.0036),),
        line=636,
        quote="The average trajectory is a straight line",
        verdict="by construction",
    ),
    Claim(
        "single-curved", "3.3.1",
        "Single movements are slightly curved, as human arm movements are",
        "slightly curved in the same way as human arm movements",
        "Fig. 3.4(a); lines 622, 632",
        "signed largest distance of each repetition from the start-goal line: human reaches "
        "curve consistently to one side, so 'in the same way' needs the repetitions to bow to "
        "one side (a sign test, p < 0.05) with a mean signed deviation beyond 2 standard "
        "errors; the unsigned size is the scatter of Fig. 3.4(a), not curvature",
        rule=(below("sign_test_p", 0.05), above("abs_mean_signed_m", "se_m", 2)),
        line=622,
        quote="slightly curved in the same way as human arm movements",
    ),
    Claim(
        "goal", "3.2.2.3",
        "The cost weights give a good tradeoff: the hand reaches the target and halts",
        "r = 0.002 (with w_v = 0.1, w_f = 0.01) 'provided a good tradeoff between error and "
        "effort'",
        "3.2.2.3; lines 537, 552",
        "Fig. 3.4's reach: the expected path's systematic miss against the repetitions' "
        "end-point SD, and the mean speed at the end; holds if the miss is within the scatter "
        "and the hand has slowed below 5 % of its peak speed. The thesis gives no movement time"
        " for it: judged at 500-1000 ms, conditional where the verdict flips with it",
        rule=(holds("reaches_and_halts"),),
        line=552,
        quote="a value of r = 0.002 provided a good tradeoff between error and effort",
    ),
    Claim(
        "sd-falls-reach", "3.3.1",
        "End-point SD falls as movement time grows (point-to-point)",
        "decreases (Fitts)",
        "Fig. 3.5; line 624",
        "end-point SD of the repetitions at the thesis's 8 movement times (500-1200 ms); the "
        "thesis gives no threshold, so the noise's: agree if the SD at the slowest is below the"
        " fastest's by more than twice the standard error of the difference (an SD from n "
        "repetitions: SD / sqrt(2 (n - 1))) and its Spearman correlation with movement time is "
        "negative beyond chance (one-sided p < 0.05)",
        rule=(above("fall_m", "se_m", 2), below("trend_p", 0.05)),
        line=624,
        quote="decrease in end-point standard deviation with increasing movement time",
    ),
    Claim(
        "s-via-points", "3.3.2",
        "The 's' passes near its via-points",
        "passes the via-points",
        "Fig. 3.6(a,c); line 652",
        "closest approach of the expected (noise-averaged) path to each via-point, and its "
        "end's distance from the goal, against the repetitions' positional SD at the "
        "via-point's time and at the end (the scatter the figure's 50 paths show): agree if "
        "every miss is below 2 SD",
        rule=(holds("every_miss_within_2sd"),),
        line=652,
        quote="a pre-specified via-point at (-0.4, 0.4)",
    ),
    Claim(
        "s-bells", "3.3.2",
        "The 's' speed: a bell per stroke, slowing at the bends",
        "three bells",
        "Fig. 3.6(b,d); line 654",
        "speed peaks (prominence 5 % of the maximum) of the mean profile; agree if three",
        rule=(equals("speed_peaks", 3),),
        line=654,
        quote="with slowing at the bends of the 's'",
    ),
    Claim(
        "sd-falls-s", "3.3.2",
        "End-point SD falls as movement time grows (the 's')",
        "decreases, less clearly",
        "Fig. 3.7; line 664",
        "end-point SD of the repetitions at the thesis's 8 movement times (500-1200 ms); the "
        "thesis gives no threshold, so the noise's: agree if the SD at the slowest is below the"
        " fastest's by more than twice the standard error of the difference (an SD from n "
        "repetitions: SD / sqrt(2 (n - 1))) and its Spearman correlation with movement time is "
        "negative beyond chance (one-sided p < 0.05)",
        rule=(above("fall_m", "se_m", 2), below("trend_p", 0.05)),
        line=664,
        quote="the end-point standard deviation decreased as movement speed decreased",
    ),
    Claim(
        "a-stops", "3.3.2",
        "The 'a': the velocity drops to about zero at the reversal",
        "≈ 0",
        "Fig. 3.8(b); line 672",
        "slowest speed between 55 and 85 % of the movement, on the expected path and per "
        "repetition; agree below 10 % of the peak speed. The thesis gives no movement time for "
        "Fig. 3.8: judged over the letter's duration sweep, conditional where the verdict flips"
        " with it",
        rule=(below("slowest_speed", "peak_speed", 0.1),),
        line=672,
        quote="where the velocity drops to zero",
    ),
    Claim(
        "a-reversal-70", "3.3.2",
        "The 'a': the reversal comes at about 70 % of the movement",
        "≈ 70 %",
        "Fig. 3.8(b); line 672",
        "time of that slowest speed",

        line=672,

        quote="at approximately 70% of the movement time",
        verdict="by construction",
    ),
    Claim(
        "a-keeps-shape", "3.3.2",
        "The 'a' keeps its shape at three movement times",
        "very similar paths",
        "Fig. 3.9(a); lines 676, 684",
        "Hausdorff distance of each mean path from the slowest's, against the repetition noise:"
        " within it if below the median Hausdorff distance of a single repetition from its own "
        "mean path ({scatter_mm:.1f} mm at {slowest_ms:.0f} ms); the movement times are swept to "
        "where the distance "
        "crosses the noise (expected paths), and the verdict holds only on one side",
        rule=(holds("keeps_at_every_time"),),
        line=676,
        quote="The shape is maintained",
    ),
    Claim(
        "a-fastest-crudest", "3.3.2",
        "The fastest 'a' is the crudest and noisiest",
        "fastest cruder, noisier",
        "Fig. 3.9; lines 676, 684",
        "largest via-point miss of the mean path and mean positional SD, {trials} repetitions per "
        "movement time; agree if both are largest at the fastest",
        rule=(holds("fastest_largest_both"),),
        line=684,
        quote="repeated with three different movement times",
    ),
)
