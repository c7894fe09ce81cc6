"""The paper's study: its recipe of runs (:mod:`~quadimpact.studies.paper.paper_study`, ``quadimpact
reproduce``), its findings as computed verdicts (:mod:`~quadimpact.studies.paper.findings`)
and the report (:mod:`~quadimpact.studies.paper.paper_report`)."""
