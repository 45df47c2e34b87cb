"""What a page or a figure shows of a design, evaluated.

The reports (:mod:`optdesign.reports`) and the plots (:mod:`optdesign.plots`) format and
draw; they evaluate no model. What they show of a design - its objectives, its binding
and violated constraint rows, its curves over the stroke, its sketch at the stroke's
ends and middle, the facts a user reads (mean ratio, ratio range, drive efficiency, the
motor) - is evaluated here, once, into typed frozen records:

- :mod:`optdesign.views.curves`: :class:`~optdesign.views.curves.StrokeCurves`;
- :mod:`optdesign.views.sketches`: :class:`~optdesign.views.sketches.SketchFrame`;
- :mod:`optdesign.views.facts`: :class:`~optdesign.views.facts.DesignFacts`;
- :mod:`optdesign.views.time_response`: :class:`~optdesign.views.time_response.
  TimeResponseView`, a design's step response in its position loop (a solve's page of a
  problem with ``[loop]``);
- :mod:`optdesign.views.design`: :class:`~optdesign.views.design.DesignRows` and
  :class:`~optdesign.views.design.DesignView`, all of the above for one design.

The layer sits above the problem and the solvers (whose rows it evaluates) and below
the studies, the reports and the plots that read its records.
"""
