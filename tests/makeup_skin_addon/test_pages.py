"""numpy's huge-page request turned off for a block and set back after
(makeup_skin_addon.pages)."""

import threading

import pytest


def test_the_block_turns_huge_pages_off_and_sets_them_back(addon):
    from makeup_skin_addon import pages

    switch = pages._switch()
    if switch is None:
        pytest.skip("this numpy has no huge-page switch")
    before = switch(True)
    try:
        with pages.ordinary():
            assert switch(False) is False  # off inside (the switch returns what it replaced)
        assert switch(True) is True  # set back as it was
        with pytest.raises(ValueError), pages.ordinary():
            raise ValueError
        assert switch(True) is True  # set back after an error too

        def setting():  # the switch's setting, read by setting it and back
            value = switch(False)
            switch(value)
            return value

        inside = pages.ordinary()(setting)
        assert inside() is False and inside() is False  # a decorator: each call its block
        assert switch(True) is True
        seen = []
        worker = threading.Thread(target=lambda: seen.append(inside()))
        worker.start()
        worker.join()
        assert seen == [True]  # a worker thread's block leaves the switch alone
        assert switch(True) is True
    finally:
        switch(before)
