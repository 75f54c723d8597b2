"""The course layer: notebook tooling (:mod:`.notebooks`), the course's trained models
(:mod:`.models`), stable printing of round-off (:mod:`.display`) and the ``python -m meshvae_lib.course`` commands (:mod:`.commands`)."""
