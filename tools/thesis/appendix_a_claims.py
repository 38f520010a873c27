"""Appendix A's claims (via-point selection and generalisation, Figs. A.1-A.3), as data.

Measured by :mod:`tools.thesis.appendix_a`; checked by :func:`tools.thesis.claims.evaluate`.
"""

from tools.thesis.claims import Claim, above, at_most, below, holds

CLAIMS = (
    Claim(
        "acceleration-captures", "A.1",
        "Acceleration extrema capture the original movement well",
        "captures well",
        "Fig. A.1(a); line 1339",
        "mean MSD per sample of the replay; agree if acceleration's is no worse than speed's",
        rule=(at_most("acceleration_msd", "speed_msd"),),
        line=1339,
        quote="maxima and minima of acceleration captures the original trajectory well",
    ),
    Claim(
        "curvature-best", "A.1",
        "Curvature extrema give the best MSD × number of via-points",
        "curvature best",
        "Fig. A.1(b); lines 1337, 1339",
        "score (MSD per sample × points stored, Fig. A.1(b)) of each criterion on each of "
        "{repetitions} "
        "repetitions; 'generally ... the best' (line 1339) read per repetition: agree if "
        "curvature scores lowest on most repetitions against each other criterion, resolved by "
        "a two-sided sign test (p < 0.05); eq. A.1 in metres and seconds (the unit table)",
        rule=(holds("curvature_wins_each"),),
        line=1339,
        quote="maxima and minima of curvature results in the best replicated trajectory for the "
              "least"
        " number of points",
    ),
    Claim(
        "curvature-landmarks", "A.1",
        "Curvature via-points fall at the movement's start, where its speed rises, at its peak "
        "speed, at the start of the post-movement period and at its end",
        "those five places",
        "Fig. A.2; line 1351",
        "every repetition of Fig. A.1's set, eq. A.1 in metres: each landmark (speed first / "
        "last above 5 % of its peak, the peak) needs a curvature point within 50 ms; start and "
        "end are always stored; agree if all three are hit on most repetitions, resolved by a "
        "two-sided sign test (p < 0.05; the figure draws one)",
        rule=(above("all_hit", "repetitions", 0.5), below("sign_test_p", 0.05)),
        line=1351,
        quote="the start of the post-movement period",
    ),
    Claim(
        "retimed-shape", "A.2",
        "Re-timed (eq. A.3) the 'a' keeps its basic shape",
        "shape retained, cruder when faster",
        "Fig. A.3(a); lines 1358, 1364",
        "Hausdorff distance between the expected paths, against the repetition noise: agree if "
        "below twice the median Hausdorff distance of a single repetition of the original from "
        "its mean path ({scatter_mm:.1f} mm; the thesis allows 'cruder', so twice what noise alone"
        " does); "
        "the re-timing is swept, and the verdict holds only where it does not turn on it",
        rule=(below("shape_m", "scatter_m", 2),),
        line=1364,
        quote="the basic same is retained",
    ),
    Claim(
        "scaled-half", "A.2",
        "Scaled by 1/2 (eqs. A.4-A.5) the 'a' is the same letter, half size",
        "same shape, half size",
        "Fig. A.3(b); lines 1364-1366",
        "largest distance between the scaled replay and the original's path scaled by 1/2; "
        "agree within 5 % of the scaled letter's height",
        rule=(below("scaled_error_m", 0.05 * 0.5 * 0.10),),
        line=1364,
        quote="scaled by a factor of",
    ),
)
