"""Chapter 5's claims (HAMMER-MV action perception from video), as data.

One row per claim and generator of clips: ``{generator}`` in a claim is the
generator's name, ``{reference}`` the reference (normal) grasp model. Measured by
:mod:`tools.thesis.ch5_rule`, :mod:`tools.thesis.ch5_shape` and
:mod:`tools.thesis.ch5_fixed`; checked by :func:`tools.thesis.claims.evaluate`. The
``verdict-*``, ``auc``, ``likelihood`` and ``aperture-sd`` rows are our own checks;
the others are the thesis's, judged under every reading of eqs. 5.1/5.7
(:mod:`tools.thesis.ch5_readings`) where the confidence rule enters.
"""

from tools.thesis.claims import Claim, above, at_least, at_most, below, holds

#: Which reading of eqs. 5.1/5.7 the thesis's own words and figure support, per claim id
#: (every row is scored under all of them).
READING = {
    "peak": "the figure's shape (a peak at maximum aperture, a fall after it) matches the "
    "printed reading; the text (line 1070) is ours",
}

CLAIMS = (
    Claim(
        "verdict-normal", "5.3 (verdict; issue 10)",
        "{generator} clips from video: normal clips get the verdict normal",
        ">= 95 % (issue 10 acceptance)",
        "issue 10 (not in the thesis; 5.3 picks the most confident model, line 1061)",
        "share of the condition's clips, rendered and tracked, whose verdict is the condition's",
        rule=(at_least("right", 0.95),),
        kind="own",
    ),
    Claim(
        "verdict-abnormal", "5.3 (verdict; issue 10)",
        "{generator} clips from video: abnormal clips get the verdict abnormal",
        ">= 95 % (issue 10 acceptance)",
        "issue 10 (not in the thesis; 5.3 picks the most confident model, line 1061)",
        "share of the condition's clips, rendered and tracked, whose verdict is the condition's",
        rule=(at_least("right", 0.95),),
        kind="own",
    ),
    Claim(
        "verdict-reach", "5.3 (verdict; issue 10)",
        "{generator} clips from video: reach clips get the verdict reach",
        ">= 95 % (issue 10 acceptance)",
        "issue 10 (not in the thesis; 5.3 picks the most confident model, line 1061)",
        "share of the condition's clips, rendered and tracked, whose verdict is the condition's",
        rule=(at_least("right", 0.95),),
        kind="own",
    ),
    Claim(
        "auc", "5.3 (verdict; issue 10)",
        "{generator}: familiarity tells normal from abnormal grasps (ROC AUC)",
        "—",
        "issue 10 (not in the thesis; 5.3, line 1061)",
        "ROC AUC of the best model's familiarity, normal clips against delayed and "
        "open-close-open ones",
        rule=(at_least("auc", 0.95),),
        kind="own",
    ),
    Claim(
        "likelihood", "5.3 (likelihood rule)",
        "{generator}: the best grasp model's log-likelihood is higher for every normal clip "
        "than for every abnormal one",
        "—",
        "5.3, line 1061",
        "the best grasp model's final log-likelihood: lowest normal minus highest abnormal",
        rule=(above("gap", 0),),
        kind="own",
    ),
    Claim(
        "final-delayed", "5.4.3, Fig. 5.8",
        "{generator}: final confidence of {reference}, normal > delayed",
        "significantly higher for normal grasps",
        "5.4.3, Fig. 5.8; lines 995, 1156",
        "the reference model's final C: share of pairs, median margin, Welch t, Hedges' g",
        rule=(at_least("pairs", 0.95), at_least("margin", 0.10), below("p", 0.01)),
        line=995,
        quote="significantly higher confidences when presented with normal grasps",
    ),
    Claim(
        "final-open-close-open", "5.4.3, Fig. 5.8",
        "{generator}: final confidence of {reference}, normal > open-close-open",
        "significantly higher for normal grasps",
        "5.4.3, Fig. 5.8; lines 995, 1156",
        "the reference model's final C: share of pairs, median margin, Welch t, Hedges' g",
        rule=(at_least("pairs", 0.95), at_least("margin", 0.10), below("p", 0.01)),
        line=995,
        quote="significantly higher confidences when presented with normal grasps",
    ),
    Claim(
        "first-half", "5.4.3, Fig. 5.8(a)",
        "{generator}: delayed opening rises little over the first half",
        "no significant increase during the first half (digits still closed)",
        "5.4.3, Fig. 5.8(a); line 1139",
        "rise of C and of its grip and transport terms up to 50 % of the movement, as shares of"
        " normal's",
        rule=(below("mean", "se", 2),),
        line=1139,
        quote="does not show any significant increase in value during the first half",
        against=(1125, "the relative contribution of each component of the movement to the "
                 "overall confidence is the same",
                 "Line 1125 sets w_r / w_g so that the transport and grip terms contribute the "
                 "same; a delayed grasp's transport is a normal one, and the hand covers most of "
                 "its path in the first half, so with equal contributions its confidence must "
                 "rise there through the transport term, which line 1139 says it does not."),
    ),
    Claim(
        "gradual", "5.4.3, Fig. 5.8(a)",
        "{generator}: delayed rises gradually once the digits open, to a relatively low final "
        "value",
        "a gradual increase ... a relatively low final confidence value",
        "5.4.3, Fig. 5.8(a); line 1152",
        "rise of C over 50-100 % of the movement, and the final C against normal's",
        rule=(above("rise", "rise_se", 2), above("lead", "lead_se", 2)),
        line=1152,
        quote="causing a gradual increase in the confidence level",
    ),
    Claim(
        "rate", "5.4.3, Fig. 5.8(a,c)",
        "{generator}: the rate of increase over the second half is greatest for normal",
        "still greater for the prediction against the observed normal grasp than for either of "
        "the other two",
        "5.4.3, Figs. 5.8(a,c); line 1154",
        "rise of C over 50-100 %, normal against each other stimulus",
        rule=(holds("beyond_2se_each"),),
        line=1154,
        quote="the rate of confidence increase during the second half of the movement is still "
        "greater",
    ),
    Claim(
        "follows", "5.4.3, Fig. 5.8(a)",
        "{generator}: open-close-open follows normal until the unexpected closing",
        "closely follows the trend of the normal movement until the point of the sudden digit "
        "closure",
        "5.4.3, Fig. 5.8(a); line 1154",
        "mean C where the closing starts (the open-close-open clips' own first aperture peak, "
        "median, in time since the onset), normal against open-close-open",
        rule=(below("abs_gap", "gap_se", 2),),
        line=1154,
        quote="closely follows the trend of the normal movement until the point of the sudden "
              "digit "
        "closure",
    ),
    Claim(
        "oco-mean", "5.4.3, Fig. 5.8(c)",
        "{generator}: the mean open-close-open profile falls after the unexpected closing "
        "(beyond normal's fall over the same window), then recovers",
        "a notable descending trend after the sudden closure, then a gradual increase as the "
        "digits re-open",
        "5.4.3, Fig. 5.8; line 1154",
        "fall of C from its peak before the closing's deepest point, as a share of the peak",
        rule=(above("ci_low", "normal_fall"), holds("recovers")),
        line=1154,
        quote="a notable descending trend followed by a gradual increase",
    ),
    Claim(
        "oco-each", "5.4.3, Fig. 5.8(b)",
        "{generator}: each open-close-open clip's profile falls (beyond every normal clip's "
        "fall) and recovers",
        "a notable descending trend after the sudden closure, then a gradual increase as the "
        "digits re-open",
        "5.4.3, Fig. 5.8; line 1154; line 1156",
        "fall of C from its peak before the closing's deepest point, as a share of the peak",
        rule=(at_least("share_beyond", 0.95), at_least("share_recovered", 0.95)),
        line=1156,
        quote="This pattern is reproduced amongst all captured trajectories",
    ),
    Claim(
        "peak", "5.4.3, Fig. 5.8(a)",
        "{generator}: normal's confidence peaks at maximum aperture and falls slightly after it",
        "maximum at the point of maximum aperture, then a slight reduction",
        "5.4.3, Fig. 5.8(a); line 1137",
        "phase of C's maximum against the maximum aperture's; fall after it",
        rule=(at_most("peak_from_mga", 0.15), at_least("fall", 0.01)),
        line=1137,
        quote="reaching its maximum at the point of maximum aperture and subsequently reducing "
        "slightly",
    ),
    Claim(
        "sd", "5.4.3, Fig. 5.8(c)",
        "{generator}: the confidence varies little between normal clips, and most for delayed "
        "in the first half and for open-close-open at the closing",
        "bars small for normal; delayed: during the first half; open-close-open: where it "
        "begins to close",
        "5.4.3, Fig. 5.8(c); line 1156",
        "SD across clips of C's rise within windows of normalised movement time",
        rule=(holds("normal_least"), holds("delayed_most_in_first_half"),
              holds("oco_most_at_closing")),
        line=1156,
        quote="These bars are small for the prediction against the normal grasp",
    ),
    Claim(
        "weights", "5.4.2",
        "{generator}: with w_r / w_g = 1/2 the transport and grip terms contribute the same",
        "the relative contribution of each component ... is the same",
        "5.4.2; line 1125",
        "transport term's share of the summed |dC| on normal clips",
        rule=(below("share_from_half", "se", 2),),
        line=1125,
        quote="the relative contribution of each component of the movement to the overall "
              "confidence "
        "is the same",
    ),
    Claim(
        "selection", "5.3",
        "{generator}: the model with the highest confidence is the observed action's",
        "the inverse model with the highest confidence value, i.e. the one that is the closest "
        "match ... is selected",
        "5.3; lines 1033, 1061",
        "kind of the model with the highest final thesis-rule confidence, normal and reach "
        "clips",
        rule=(holds("most_pick_their_kind"),),
        line=1061,
        quote="the model with the highest confidence can be selected",
    ),
    Claim(
        "aperture", "5.4.1, Fig. 5.4(d)",
        "{generator}: the normal grasp's aperture is like the model's",
        "similar profiles",
        "5.4.1, Fig. 5.4(d); line 1093",
        "maximum aperture and its time against the reference model's own",
        rule=(at_most("mga_gap_m", 0.02), at_most("time_gap", 0.1)),
        line=1093,
        quote="the similarity between the grip aperture profile",
    ),
    Claim(
        "aperture-sd", "5.4.1, Fig. 5.4(d)",
        "{generator}: aperture varies more for the abnormal grasps",
        "variances greater for the non-natural grips",
        "5.4.1, Fig. 5.4(d); line 1109",
        "largest SD across clips of the aperture over normalised movement time",
        rule=(holds("abnormal_above_normal"),),
        kind="own",
    ),
    Claim(
        "prediction", "5.4.3, Figs. 5.5-5.7",
        "{generator}: the normal grasp model's own movement is close to the normal "
        "demonstrations and far from the abnormal ones",
        "similar for normal; large differences for the non-natural actions",
        "5.4.3, Figs. 5.5-5.7; line 1133",
        "median |observed - model's own| aperture over the movement",
        rule=(holds("abnormal_beyond_1_5_normal"),),
        line=1133,
        quote="how similar the predicted movement is to the observed movement",
    ),
)
