"""What a closure fit gives the node group (lut_baker.closures.closure_fit)."""





def test_summary_is_plain_data(paper_fit):
    import json

    text = json.dumps(paper_fit.summary())
    assert "PRINCIPLED" in text and "subsurface_method" in text
