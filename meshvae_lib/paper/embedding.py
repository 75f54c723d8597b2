"""Sec. 5.4: 2D embeddings (sigma_object VAE, PCA, NPE, t-SNE) and their retrieval AUC."""

from __future__ import annotations

from meshvae_lib import defaults as hp
from meshvae_lib.model.train_config import pad_sigma_object
from meshvae_lib.paper.protocol import load_collection, name_of, timed, train_model
from meshvae_lib.paper.settings import PAPER, ExperimentSettings, resolve_settings
from meshvae_lib.paper.tables import ExperimentTable

__all__ = ["embedding_table"]


def _vae_runs(coll, s, cache, labels, relevance, seeds, prior, alpha, hidden, epochs):
    """One sigma_object VAE per seed: ``({seed: (embedding, PR result)}, the median seed, the last
    model)``."""
    from meshvae_lib.applications import retrieval as ret

    so = pad_sigma_object(hp.EMBEDDING_SIGMA_OBJECT, s.latent_dim)
    out = {}
    for sd in seeds:
        m = train_model(coll, s, cache, sigma_object=so, holdout=False, prior=prior, alpha=alpha, hidden=hidden,
                        seed=sd, epochs=epochs)
        y = m.encode_meshes(coll.vertices, inference="encoder")[:, :2]
        out[sd] = (y, ret.precision_recall_curve(y, labels, relevance=relevance))
    order = sorted(seeds, key=lambda sd: out[sd][1].auc["mean"])
    return out, order[(len(order) - 1) // 2], m


def _baselines(X, labels, relevance, seed) -> tuple[dict, dict]:
    """t-SNE, PCA and NPE of the rows ``X``: ({method: embedding}, {method: PR result})."""
    from meshvae_lib.applications import embedding as emb
    from meshvae_lib.applications import retrieval as ret

    k = min(hp.NPE_N_NEIGHBORS, len(X) - 1)
    Y = {
        "t-SNE": emb.tsne_embedding(X, seed=seed),
        "PCA": emb.pca_embedding(X, seed=seed),
        "NPE": emb.NeighborhoodPreservingEmbedding(2, n_neighbors=k).fit_transform(X),
    }
    return Y, {m: ret.precision_recall_curve(y, labels, relevance=relevance) for m, y in Y.items()}


def _table(name, Y, curves, labels, seed_aucs, seeds) -> ExperimentTable:
    from meshvae_lib.applications import retrieval as ret

    cols = ["method", "AUC (mean)"] + [f"AUC {c}" for c in labels] + ["AUC joint", "seeds (min-max)", "paper AUC"]
    table = ExperimentTable("embedding_auc", f"Sec. 5.4: retrieval AUC of 2D embeddings ({name})", cols)
    for m, y in Y.items():
        res = curves[m]
        joint = ret.retrieval_auc(y, labels, relevance="joint") if len(labels) > 1 else res.auc["mean"]
        spread = (f"{min(seed_aucs[m]):.4f}-{max(seed_aucs[m]):.4f}" if m in seed_aucs and len(seeds) > 1 else None)
        table.rows.append([m, res.auc["mean"]] + [res.auc[c] for c in labels] + [joint, spread, PAPER["auc"].get(m)])
    return table


@timed
def embedding_table(collection: str = "dyna", label_columns=("shape", "motion"), relevance: str = "each",
                    compare_exact: bool = True, compare_paper_defaults: bool = True,
                    seeds=hp.EMBEDDING_SEEDS, alpha: float = hp.EMBEDDING_ALPHA, hidden=hp.EMBEDDING_HIDDEN,
                    settings: ExperimentSettings | None = None, quick: bool = False,
                    cache: dict | None = None) -> ExperimentTable:
    """Sec. 5.4: 2D embeddings and their retrieval precision-recall AUC.

    The sigma_object VAE (deviations 0.1 for the first two latent dimensions, 1 for the rest, the
    sibling-code form of the latent cost) is trained on the whole collection with reconstruction
    weight ``alpha`` and internal layers ``hidden``, once per seed; its embedding is the first two
    encoder means and its row is the seed with the median AUC (all seeds' AUCs are in the notes and
    in ``data["seed_aucs"]``). PCA, NPE (k = 25) and t-SNE (perplexity 30) embed the same
    normalised RIMD feature rows the VAE sees. Relevance: see :mod:`meshvae_lib.applications.embedding`
    ("each": per label column, averaged).

    Extra rows: ``compare_exact`` -- the same model with the exact KL; ``compare_paper_defaults`` --
    the sibling form with the paper's general settings (alpha = 1e6, no internal layer).
    """
    s = resolve_settings(settings, quick)
    coll = load_collection(collection, s, cache=cache)
    labels = {c: coll.labels[c] for c in label_columns if c in coll.labels}
    if not labels:
        raise ValueError(f"collection {name_of(collection)!r} has none of the label columns {label_columns};"
                         f" it has {sorted(coll.labels)}")
    seeds = [int(x) for x in seeds]
    if not seeds:
        raise ValueError("give at least one seed")
    ep = s.embedding_epochs_for(len(coll.vertices))
    runs = lambda prior, a, h: _vae_runs(coll, s, cache, labels, relevance, seeds, prior, a, h, ep)  # noqa: E731

    ours, med, model = runs("sibling", alpha, hidden)
    X = model.features_of(coll.vertices)  # the normalised rows every model saw (fitted on all meshes)
    base, base_curves = _baselines(X, labels, relevance, s.seed)
    Y = {"sigma_object VAE": ours[med][0], **base}
    curves = {"sigma_object VAE": ours[med][1], **base_curves}
    seed_aucs = {"sigma_object VAE": [ours[sd][1].auc["mean"] for sd in seeds]}
    extra = []
    if compare_exact:
        extra.append(("sigma_object VAE, exact KL", "exact", alpha, hidden))
    if compare_paper_defaults:
        extra.append(("sigma_object VAE, alpha 1e6, no hidden layer", "sibling", hp.DEFAULT_ALPHA, ()))
    for name, prior, a, h in extra:
        other, m, _ = runs(prior, a, h)
        Y[name], curves[name] = other[m]
        seed_aucs[name] = [other[sd][1].auc["mean"] for sd in seeds]

    table = _table(name_of(collection), Y, curves, labels, seed_aucs, seeds)
    table.data.update(embeddings=Y, labels=labels, curves=curves, seed_aucs=seed_aucs, seeds=seeds, median_seed=med,
                      alpha=float(alpha), hidden=tuple(hidden), epochs=ep)
    ours_auc = table.rows[0][1]
    others = {r[0]: r[1] for r in table.rows[1:4]}
    table.data["ours_minus"] = {m: ours_auc - a for m, a in others.items()}
    table.notes.append(f"N = {len(X)} meshes; relevance = {relevance!r} (one retrieval task per label, AUCs averaged)."
                       f" Ours minus t-SNE: {ours_auc - others['t-SNE']:+.4f}, minus PCA: {ours_auc - others['PCA']:+.4f},"
                       f" minus NPE: {ours_auc - others['NPE']:+.4f}.")
    table.notes.append(f"sigma_object VAE: sibling-form latent cost, alpha = {alpha:g}, hidden layers {list(hidden)},"
                       f" {ep} epochs; the row is the median of seeds {seeds} (AUC per seed: "
                       + ", ".join(f"{a:.4f}" for a in seed_aucs["sigma_object VAE"]) + ").")
    return table
