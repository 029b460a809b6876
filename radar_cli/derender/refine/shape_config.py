"""The shape fit's settings (derender.refine.fit_shape, its pitch cues derender.refine.pitch_cues;
docs/refinement.md)."""

from __future__ import annotations

from dataclasses import dataclass

from radar_cli.derender.refine.bands import BandCue


@dataclass(frozen=True)
class ShapeFitConfig:
    """How the shape and pose are fitted (weights chosen on 24 vases of `radar synth --size 512 --seed 5`;
    docs/refinement.md).

    Attributes:
        rows: profile rows fitted.
        grid_size: outline resolution of the pitch grids (px).
        pitch_max: the grids cover 0..pitch_max degrees.
        coarse_step, fine_step: the pitch grids (the fine one spans +- coarse_step round the coarse pick).
        roughness_weight: the profile's bending (sum of squared second differences x 1e3, at 64 rows).
        corner: a second difference counts at most this much (a moulding, a lip, a foot's step is a corner of a
            real profile: charged once, whatever its size; None: no cap). Uncapped, the steps of an overhanging
            rim and a stepped foot, sharp at the right (level) pitch, are smoothed by the ellipses of a steep
            one, and the bending term drove level photographs of kraters to 10-25 deg.
        basin: the lip may pick any candidate whose outline score is within this of the best.
        cue_basin_px: the lip and the bands pick only among candidates whose top edge (the rim's back arc
            where the mouth shows) is within this of the best one's (px at grid_size; None: no such bound):
            where the photograph's top edge is straight, the rim is seen edge on and no mouth is drawn, whatever
            edge or pattern below it looks like a lip.
        end_px: the profile's end rows are read at least this far (px at 256) inside the outline's first and
            last rows (profile_from_widths).
        lip_contrast: the lip is trusted where its contrast (grey levels 0..1) exceeds this.
        band_ratio: painted bands pick the pitch where their coherence peaks at least this many times its lowest
            over the grid.
        band_reach: where they do, the lip is looked for within this of their peak (degrees).
        lip_over_bands: a lip above this contrast outside the bands' reach is looked at instead where no lip
            (lip_contrast) lies within their reach and its top edge is the better (pitch_cues._lip_over_bands;
            None: the bands always bound the lip).
        dark_lip_over_bands: the same for a lip relative to its sides' grey level (lip_relative) above this, where
            no such lip above lip_relative lies within their reach either (a black mouth over a dark neck or a
            glaze's edge: steep synthetic vases read 0.85-0.97 where dots or a glaze's edge made a band; None:
            not looked at).
        bands: how the bands are read (derender.refine.bands).
        prior_reach: without bands or a lip, the outline's pick stays at most this above the network's pitch (degrees);
            below it the outline is free (the network reads low pitches too high; a thick rim or a bevelled foot
            makes the outline read too high).
        lip_tie: coarse candidates whose lip is at least this fraction of the strongest count as tied; the
            outline picks among them.
        lip_relative: without a lip above lip_contrast, one whose contrast divided by its two sides' mean grey
            level (plus lip_dark) exceeds this is trusted (a black mouth over a dark neck: a faint edge, but
            the mouth is several times darker; None: not looked for), on an arc at least lip_share of which
            is darker above than below. Steep synthetic vases with a dark neck read 0.36-1.7 with shares of
            0.93-1.0; the arcs of steep candidates on level photographs of kraters up to 0.50, with shares of
            at most 0.85 (a decorated neck or rim crosses them).
        lip_share: see lip_relative.
        straight_ratio, straight_rise_px: on the coarse grid, an arc rising at least straight_rise_px (px at 512
            px) over its middle 80 % whose contrast a level line across the same columns reaches straight_ratio
            times (pitch_cues.straight_contrast) is no lip (None: not checked). A level photograph's rim and neck
            meet in straight edges, which the arcs of steep candidates cross: on the CVA 10 side views (and
            lighter, darker, warmer copies) such arcs read 0.10-0.15 and their best line 1.2-2.5 x that, while
            the open mouths of 120 synthetic vases at 512 px (seeds 5, 7, 31) read 0.55-0.98 x on the arcs that
            picked their pitch (one 1.08 x, beside a neighbour at 0.92 that picks instead).
        lip_dark: grey level added to the sides' mean before dividing (two black sides make no lip).
        dark_lip_bands: the relative lip picks only among candidates whose painted bands' coherence is at least
            this share of the basin's highest (bands too faint to pick still say which pitches they rule out:
            an oinochoe's trefoil mouth shows its dark inside at a level view; None: not checked).
        lip_offset_px, fine_lip_offset_px: the lip's two sides are sampled this far above and below the arc (px
            at 512 px), on the coarse grid (wide: finds the lip) and on the fine one (narrow: places it).
        width_rounds: rounds of correct_widths at full resolution after the search.
        lip_width_rounds: rounds of correct_widths for the search's candidates outside the basin (or the top
            edge's, cue_basin_px) that show a strong lip, before they are scored again (fit_shape._second_look;
            0: none).
        polish_steps: Adam steps at grid_size, then at full resolution, pitch held.
        polish_lr: their step (radii, height and offsets in hundredths of r_max, roll in degrees).
        placement_iterations: closed-form rounds of profile, height and vertical offset per candidate.
        smooth_hidden: after the polish, the profile's rows that no end of the outline depends on are drawn with
            the least bending (derender.refine.hidden_rows).
    """

    rows: int = 64
    grid_size: int = 256
    pitch_max: float = 25.0
    coarse_step: float = 0.5
    fine_step: float = 0.1
    roughness_weight: float = 0.5
    corner: float | None = 0.005
    basin: float = 3.0
    cue_basin_px: float | None = 1.0
    end_px: float = 2.0
    lip_contrast: float = 0.1
    lip_tie: float = 0.9
    lip_relative: float | None = 0.35
    lip_share: float = 0.9
    straight_ratio: float | None = 1.0
    straight_rise_px: float = 6.0
    lip_dark: float = 0.02
    dark_lip_bands: float | None = 0.6
    prior_reach: float = 3.0
    band_ratio: float = 8.0
    band_reach: float = 1.0
    lip_over_bands: float | None = 0.25
    dark_lip_over_bands: float | None = 0.6
    bands: BandCue = BandCue()
    lip_offset_px: float = 2.0
    fine_lip_offset_px: float = 1.0
    width_rounds: int = 3
    lip_width_rounds: int = 1
    polish_steps: tuple[int, int] = (40, 10)
    polish_lr: float = 0.05
    placement_iterations: int = 3
    smooth_hidden: bool = True
