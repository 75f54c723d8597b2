"""The paper's experiments on the course's synthetic collections (paper Sec. 5, Tables 1-3).

One function per experiment, one module each; every function returns an :class:`ExperimentTable`
(rows a notebook prints with ``to_markdown()``, the raw numbers in ``data``, ``plot()`` for a
matplotlib figure)::

    from meshvae_lib import paper
    t = paper.feature_table(["jumping"], settings=paper.ExperimentSettings.quick(seed=0))

============================  ====================  ===========================================================
function                      module                experiment
============================  ====================  ===========================================================
``latent_size_table``         ``latent_size``       Table 1: held-out per-vertex error for latent sizes 16/128/256
``feature_table``             ``features``          Table 2: RIMD vs 3D coordinates vs aligned coordinates
``robustness_table``          ``robustness``        Table 3: the choice of reference (base) mesh and mesh density
``loss_table``                ``loss``              Sec. 5.1 "MSE loss": MSE vs sigmoid + binary cross-entropy
``embedding_table``           ``embedding``         Sec. 5.4: 2D embeddings (sigma_object VAE, PCA, NPE, t-SNE), AUC
``generation_table``          ``generation``        Sec. 5.2: generation, nearest neighbours, conditional generation
``interpolation_table``       ``interpolation``     Sec. 5.3 / Figs. 4 and 6: latent vs RIMD vs coordinate interpolation
``exploration_table``         ``exploration``       Sec. 5.5 / Fig. 8: what the first latent dimensions control
``noise_diversity_table``     ``noise_diversity``   not the paper's: when RIMD wins (pose diversity, capture noise)
============================  ====================  ===========================================================

The other modules: ``settings`` (:class:`ExperimentSettings`, the paper's numbers ``PAPER``),
``tables`` (:class:`ExperimentTable`, :func:`read_results`, :func:`definition_fingerprint`),
``protocol`` (:func:`load_collection`, the one way the experiments train a model, the held-out
error, the cache), ``linear_floor`` (:func:`linear_floor`: PCA on coordinates and on aligned
coordinates under every error table, and whether a row is informative) and ``plots``.

Every function takes ``settings`` (an :class:`ExperimentSettings`) or ``quick=True`` for the tiny
preset a notebook runs in well under a minute, and a ``cache`` dict shared between experiments so
that one trained model serves several tables (``benchmarks/experiments.py`` runs them all at full
size). Errors are the paper's: the mean Euclidean distance between the vertices of a held-out mesh
and of its reconstruction (encoder mean, decoder, mesh), after rigid alignment, in the mesh's units
(metres for the synthetic humans). Collections come from ``data_synth.make_collection``.

Importing this package imports neither torch nor matplotlib: the experiments import them when run.
"""

from meshvae_lib.paper.embedding import embedding_table
from meshvae_lib.paper.exploration import exploration_table
from meshvae_lib.paper.features import feature_table
from meshvae_lib.paper.generation import generation_table
from meshvae_lib.paper.interpolation import interpolation_table
from meshvae_lib.paper.latent_size import latent_size_table
from meshvae_lib.paper.linear_floor import informative_rows, linear_floor
from meshvae_lib.paper.loss import loss_table
from meshvae_lib.paper.noise_diversity import noise_diversity_table
from meshvae_lib.paper.protocol import collection_fingerprint, load_collection
from meshvae_lib.paper.robustness import robustness_table
from meshvae_lib.paper.settings import PAPER, ExperimentSettings
from meshvae_lib.paper.tables import ExperimentTable, RecordedResults, definition_fingerprint, read_results

__all__ = [
    "ExperimentSettings",
    "ExperimentTable",
    "PAPER",
    "collection_fingerprint",
    "load_collection",
    "linear_floor",
    "informative_rows",
    "latent_size_table",
    "feature_table",
    "robustness_table",
    "loss_table",
    "embedding_table",
    "generation_table",
    "interpolation_table",
    "exploration_table",
    "noise_diversity_table",
    "ALL_EXPERIMENTS",
    "definition_fingerprint",
    "RecordedResults",
    "read_results",
]

#: every experiment, in the order the runner writes them.
ALL_EXPERIMENTS = (
    latent_size_table,
    feature_table,
    robustness_table,
    loss_table,
    embedding_table,
    generation_table,
    interpolation_table,
    exploration_table,
    noise_diversity_table,
)
