"""Chapter 2's claims (section 2.2, the minimum jerk family, Figs. 2.5-2.8), as data.

Measured by :mod:`tools.thesis.ch2`; checked by :func:`tools.thesis.claims.evaluate`.
"""

from tools.thesis.claims import Claim, above, below, equals, holds

_IDENTITY = ("By construction: a closed-form property of the minimum-derivative model "
             "(nothing fitted), so it checks our implementation, not a finding.")

CLAIMS = (
    Claim(
        "jerk-straight", "2.2.2",
        "Minimum jerk hand paths are straight",
        "straight",
        "Fig. 2.5(a); line 260",
        "largest distance of each path from its start-goal line; agree below 1e-9 m (straight "
        "to rounding)",
        rule=(below("max_deviation_m", 1e-9),),
        line=260,
        quote="fit the criterion for straight hand trajectories",
        verdict="by construction", why=_IDENTITY,
    ),
    Claim(
        "jerk-bells", "2.2.2",
        "Minimum jerk speed profiles are smooth single bells",
        "bell-shaped",
        "Fig. 2.5(b); line 260",
        "speed peaks (prominence 5 % of the maximum); agree if one in every profile",
        rule=(holds("one_peak_each"),),
        line=260,
        quote="characteristic bell-shaped velocity profiles",
        verdict="by construction", why=_IDENTITY,
    ),
    Claim(
        "ratio-rises", "2.2.3",
        "r, the peak/mean velocity ratio, increases with the derivative order n",
        "increases with n",
        "Fig. 2.6(c); line 276",
        "r of the rest-to-rest minimum-derivative profile, closed form 1 / (4^(n-1) B(n, n)) "
        "(checked against profiles sampled at 1 ms); agree if it rises at every order",
        rule=(holds("rises_every_order"),),
        line=276,
        quote="the value of r increases with n",
        verdict="by construction", why=_IDENTITY,
    ),
    Claim(
        "human-nearest", "2.2.3",
        "Humans (r ≈ 1.875) are closest to minimum jerk",
        "human r = 1.875 (the dashed line); nearest order n = 3",
        "Fig. 2.6(c); lines 274, 276",
        "the order whose r is nearest the human 1.875",
        rule=(equals("nearest_order", 3),),
        line=276,
        quote="closest to minimum jerk trajectories",
        verdict="by construction", why=_IDENTITY,
    ),
    Claim(
        "angle-jerk-joints", "2.2.4",
        "Minimum angle jerk: joint paths are straight in joint space",
        "straight joint paths",
        "Fig. 2.7; line 287",
        "largest distance of each joint-space path from its start-goal line; agree below 1e-9 "
        "rad",
        rule=(below("max_deviation_rad", 1e-9),),
        line=287,
        quote="leads to straight paths in joint space",
        verdict="by construction", why=_IDENTITY,
    ),
    Claim(
        "angle-jerk-hand-path", "2.2.4",
        "Minimum angle jerk: hand path roughly straight, slightly curved",
        "slight curvature",
        "Fig. 2.8(a); lines 285, 294",
        "largest distance of each hand path from its start-goal line; 'slight' taken as 1-15 % "
        "of the movement length",
        rule=(above("min_relative_deviation", 0.01), below("max_relative_deviation", 0.15)),
        line=294,
        quote="smooth and roughly straight, with a slight degree of curvature",
    ),
    Claim(
        "angle-jerk-hand-speed", "2.2.4",
        "Minimum angle jerk hand speed is bell-shaped",
        "bell-shaped",
        "Fig. 2.8(b); line 294",
        "speed peaks (prominence 5 % of the maximum); agree if one in every profile",
        rule=(holds("one_peak_each"),),
        line=294,
        quote="the required bell-shape",
    ),
)
