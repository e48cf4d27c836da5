"""Real-files tier: files made by others (validation/real_files.py; the corpus fetched once by
scripts/fetch_corpus.sh), each through the engine as a user meets it."""
import pytest

bpy = pytest.importorskip("bpy")


def pytest_generate_tests(metafunc):
    if "corpus_file" in metafunc.fixturenames:
        from validation import real_files
        models = real_files.corpus_models()
        metafunc.parametrize("corpus_file", [(models, name) for name in real_files.corpus_files(models)],
                             ids=lambda item: item[1])


@pytest.fixture(scope="session")
def addon():
    """The add-on, registered once per process."""
    import sg_prt_addon
    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()
    return sg_prt_addon
