"""The container runtime port: what the match domain (:mod:`orchestrator.match`) asks of a
container engine and of a robot node, and what the engine finds on the host (``port``); the
ledger of the objects this runner created (``ledger``). The Docker adapter
(:mod:`orchestrator.engine`) implements it; the port imports neither of them, so that the
adapter never imports the domain. Inside ``orchestrator`` only: other packages use the match's
face."""
