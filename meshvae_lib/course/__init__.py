"""The course layer: notebook tooling (:mod:`.notebooks`), the course's trained models
(:mod:`.models`) and the ``python -m meshvae_lib.course`` commands (:mod:`.commands`)."""
