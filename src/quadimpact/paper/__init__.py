"""The paper's study: its recipe of runs (:mod:`~quadimpact.paper.study`, ``quadimpact
reproduce``), its findings as computed verdicts (:mod:`~quadimpact.paper.findings`)
and the report (:mod:`~quadimpact.paper.report`)."""
