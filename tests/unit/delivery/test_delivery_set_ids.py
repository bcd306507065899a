"""Log-set ids are unique by construction: team and match names that differ only in spaces or
punctuation are different sets, and one team's set never replaces another's."""

from __future__ import annotations

from pathlib import Path

from orchestrator.delivery.store import create_set, list_sets, set_id_of


def test_names_that_differ_in_punctuation_get_different_ids() -> None:
    teams = ["Bit Bots", "Bit_Bots", "Bit-Bots", "Bit/Bots", "Bit+Bots", "bit bots", "", ".",
             "..", "Bit%20Bots", "x" * 400, "x" * 401]
    ids = {set_id_of("m1", team) for team in teams}
    assert len(ids) == len(teams)
    assert set_id_of("a+b", "c") != set_id_of("a", "b+c")
    for set_id in ids:
        assert "/" not in set_id and not set_id.startswith(".") and len(set_id) < 255


def test_two_teams_whose_names_collided_keep_both_sets(tmp_path: Path) -> None:
    store = tmp_path / "store"
    for team in ("Bit Bots", "Bit_Bots"):
        log = tmp_path / f"{team}.log"
        log.write_text(f"{team}\n")
        create_set(store, match_id="m1", team=team, kind="team", credentials=None,
                   sources=[(log, "stdout.log")], move=False)
    sets = {s.team: s for s in list_sets(store)}
    assert set(sets) == {"Bit Bots", "Bit_Bots"}
    for team, pending in sets.items():
        assert (pending.files_dir / "stdout.log").read_text() == f"{team}\n"
